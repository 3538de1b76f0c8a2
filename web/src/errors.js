// Errors of the page's decoder: the stable ids of the C++ reader (format/include/calf/format/
// errors.h, docs/ERRORS.md), one line each.
export const E = {
  identifier: 'CALF-E040', version: 'CALF-E041', requiredFeature: 'CALF-E042',
  headerChecksum: 'CALF-E043', truncated: 'CALF-E044', fileSize: 'CALF-E045',
  directoryRange: 'CALF-E046', directoryChecksum: 'CALF-E047', directoryFormat: 'CALF-E048',
  limit: 'CALF-E049', trackKind: 'CALF-E050', trackHeader: 'CALF-E051', metadata: 'CALF-E052',
  chunkRange: 'CALF-E053', chunkLayout: 'CALF-E054', chunkTrack: 'CALF-E055',
  compression: 'CALF-E056', chunkSize: 'CALF-E057', chunkHash: 'CALF-E058',
  decompress: 'CALF-E059', padding: 'CALF-E060', chunkId: 'CALF-E061', coverageChunk: 'CALF-E065',
  coverageDepth: 'CALF-E066', av1Chunk: 'CALF-E067', av1Decode: 'CALF-E301', av1Picture: 'CALF-E302', lightfieldChunk: 'CALF-E202',
  lightfieldFormat: 'CALF-E203', playerOptions: 'CALF-E403', playbackClip: 'CALF-E460',
  tilesChunk: 'CALF-E210', tilesUnsupported: 'CALF-E211', tilesValue: 'CALF-E212', tilesLimit: 'CALF-E213',
  meshChunk: 'CALF-E220', meshUnsupported: 'CALF-E221', meshIndex: 'CALF-E222', meshValue: 'CALF-E223',
  meshLimit: 'CALF-E224',
};

export class CalfError extends Error {
  constructor(id, message) {
    super(`${id} ${message}`);
    this.id = id;
  }
}

export function fail(id, message) {
  throw new CalfError(id, message);
}
