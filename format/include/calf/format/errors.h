// calf error ids: the one list of every error a calf library can return.
//
// Each id is stable: once released, a number keeps its meaning forever, so that users, scripts
// and tests can grep for "CALF-E012". A new error takes a new number in its layer's range; a
// retired one stays in the list, marked retired. docs/ERRORS.md documents every id; the test
// tests/format/errors_test.cc fails when an id here is missing from that document.
//
// Ranges:   1- 19 general (arguments, files)      20- 39 conventions (cube, log depth, grids)
//          40- 99 container (format/SPEC.md)     100-129 BCn block codecs
//         130-149 capture sets (format/CAPTURE.md) 150-169 scene files (format/SCENE.md)
//         170-199 calf-capture and sample scenes
//         200-299 encoder    300-399 decoder    400-499 player
#pragma once

#include <cstdint>

namespace calf {

// What the caller can do about an error; derived from the id, never stored separately.
enum class ErrorKind : uint8_t {
  kInvalidArgument,  // the caller passed a value the API does not accept
  kCorrupt,          // bytes in a file are wrong: a checksum, a field, a length
  kNeedMoreData,     // the input ended early: a truncated file or stream
  kUnsupported,      // valid, but uses something this build does not implement
  kLimit,            // a size or count exceeds a documented limit
  kIo,               // the operating system refused: open, read, write, rename
  kInternal,         // an invariant of calf itself failed; a bug to report
};

// X(name, number, kind, one-line summary). The summary is the headline in docs/ERRORS.md; the
// message of each Status says which file, field or value is at fault.
// One error a line, the backslashes aligned by hand:
// clang-format off
#define CALF_ERROR_LIST(X)                                                                      \
  /* general */                                                                                 \
  X(kInvalidArgument, 1, kInvalidArgument, "an argument is outside what the API accepts")       \
  X(kFileOpen, 2, kIo, "a file could not be opened")                                            \
  X(kFileRead, 3, kIo, "a file could not be read")                                              \
  X(kFileWrite, 4, kIo, "a file could not be written or renamed into place")                    \
  X(kInternal, 5, kInternal, "an internal invariant failed")                                    \
  X(kUsage, 6, kInvalidArgument, "a command-line option or argument is invalid")                \
  X(kOutputIsInput, 7, kInvalidArgument, "an output path names one of the command's inputs")    \
  X(kImageBudget, 12, kLimit, "an image or a viewpoint's faces exceed the image budget")        \
  X(kOutOfMemory, 13, kLimit, "the command ran out of memory")                                  \
  X(kRendererUnavailable, 14, kUnsupported, "the renderer a command needs is not available")    \
  /* conventions */                                                                             \
  X(kDepthRange, 20, kInvalidArgument, "z_near / z_far do not form a valid log-depth range")    \
  X(kDepthValue, 21, kCorrupt, "a depth value is NaN, negative, zero or -inf")                  \
  X(kDepthOutOfRange, 22, kInvalidArgument, "a finite depth lies outside [z_near, z_far]")      \
  X(kGridSize, 23, kInvalidArgument, "a face, cell or tile size is zero or too large")          \
  X(kGridIndex, 24, kInvalidArgument, "a cell, tile or quadtree index is outside its grid")     \
  /* container: 40-99 */                                                                        \
  X(kContainerIdentifier, 40, kCorrupt, "the file does not start with the calf identifier")     \
  X(kContainerVersion, 41, kUnsupported, "the file's major version is not supported")           \
  X(kContainerRequiredFeature, 42, kUnsupported, "an unknown must-understand flag is set")      \
  X(kContainerHeaderChecksum, 43, kCorrupt, "the header checksum does not match")               \
  X(kContainerTruncated, 44, kNeedMoreData, "the file ends before its declared size")           \
  X(kContainerFileSize, 45, kCorrupt, "the file is longer than its header declares")            \
  X(kContainerDirectoryRange, 46, kCorrupt, "the directory is outside the file or misplaced")   \
  X(kContainerDirectoryChecksum, 47, kCorrupt, "the directory checksum does not match")         \
  X(kContainerDirectoryFormat, 48, kCorrupt, "a directory field is malformed")                  \
  X(kContainerLimit, 49, kLimit, "a count or size exceeds a container limit")                   \
  X(kContainerTrackKind, 50, kUnsupported, "a must-understand track has an unknown kind")       \
  X(kContainerTrackHeader, 51, kCorrupt, "a track header is short or holds a bad value")        \
  X(kContainerMetadata, 52, kCorrupt, "a metadata key or value is invalid")                     \
  X(kContainerChunkRange, 53, kCorrupt, "a chunk lies outside the chunk area")                  \
  X(kContainerChunkLayout, 54, kCorrupt, "a chunk is not at its canonical offset")              \
  X(kContainerChunkTrack, 55, kCorrupt, "a chunk names a track that does not exist")            \
  X(kContainerCompression, 56, kUnsupported, "a chunk uses an unknown supercompression")        \
  X(kContainerChunkSize, 57, kCorrupt, "a chunk's stored/raw lengths contradict its scheme")    \
  X(kContainerChunkHash, 58, kCorrupt, "a chunk's stored bytes do not match its hash")          \
  X(kContainerDecompress, 59, kCorrupt, "a chunk does not decompress to its raw length")        \
  X(kContainerPadding, 60, kCorrupt, "a padding byte is not zero")                              \
  X(kContainerChunkId, 61, kInvalidArgument, "a chunk id is outside the chunk index")           \
  X(kContainerBufferSize, 62, kInvalidArgument, "a buffer does not match a chunk's raw length") \
  X(kContainerWriterMisuse, 63, kInvalidArgument, "the writer got a value the format forbids")  \
  X(kContainerCompressor, 64, kInternal, "the compression library failed")                      \
  X(kCoverageChunk, 65, kCorrupt, "a coverage chunk's edge texels break their counts")        \
  X(kCoverageDepth, 66, kCorrupt, "a coverage texel contradicts its depth")                    \
  X(kAv1Chunk, 67, kCorrupt, "an AV1 colour chunk's head contradicts its size or keys")       \
  /* block codecs: 100-129 */                                                                   \
  X(kBcDimensions, 100, kInvalidArgument, "an image is empty or wider/taller than 65536 px")   \
  X(kBcBufferSize, 101, kInvalidArgument, "a pixel or block buffer is smaller than needed")    \
  X(kBcStride, 102, kInvalidArgument, "a row stride is smaller than one row of pixels")        \
  X(kBcOptions, 103, kInvalidArgument, "an encoder option or channel count is invalid")        \
  X(kBcNonFinite, 104, kInvalidArgument, "HDR input holds NaN or infinity (rejected)")         \
  X(kBcOutOfRange, 105, kInvalidArgument, "HDR input is out of the format's range (rejected)") \
  /* visible sets: 110-119 (encoder/include/calf/encoder/visible_set.h) */                        \
  X(kVisibleSetNoSegment, 110, kInvalidArgument, "no view segment or eye point was given")      \
  X(kVisibleSetSegment, 111, kInvalidArgument, "a view segment is degenerate or not finite")    \
  X(kVisibleSetOutside, 112, kInvalidArgument, "a segment or eye lies outside the scene bounds") \
  X(kVisibleSetScene, 113, kInvalidArgument, "the scene has no triangle or cannot be read")     \
  X(kVisibleSetOption, 114, kInvalidArgument, "a visible-set option is outside its range")      \
  X(kVisibleSetLimit, 115, kLimit, "the scene has more primitives than the builder accepts")     \
  /* capture sets: 130-169 */                                                                   \
  X(kManifestSyntax, 130, kCorrupt, "a manifest or eye path is not valid JSON")                 \
  X(kManifestField, 131, kCorrupt, "a manifest field is missing, mistyped or out of range")     \
  X(kManifestVersion, 132, kUnsupported, "a manifest has an unknown format or version")         \
  X(kManifestInconsistent, 133, kCorrupt, "manifest fields contradict each other")              \
  X(kCaptureLimit, 134, kLimit, "a capture set exceeds a documented size limit")                \
  X(kCaptureFileMissing, 135, kIo, "an image named by the manifest is missing")                 \
  X(kCaptureImageFormat, 136, kCorrupt, "an image has the wrong size, channels or type")        \
  X(kCaptureDepthPixel, 137, kCorrupt, "a depth pixel is NaN, -inf, zero or negative")          \
  X(kCaptureColourPixel, 138, kCorrupt, "a colour pixel is NaN, infinite or negative")           \
  X(kCaptureMaterialPixel, 139, kCorrupt, "a material pixel is outside its documented range")   \
  X(kCaptureIndex, 140, kInvalidArgument, "a view or frame index is outside the set")           \
  X(kCaptureWriterMisuse, 141, kInvalidArgument, "the capture writer got a bad buffer or call") \
  X(kEyePathField, 142, kCorrupt, "an eye path field is missing or out of range")               \
  X(kSeuratField, 143, kCorrupt, "a Seurat manifest field is missing, mistyped or unusable")    \
  X(kSeuratHeadbox, 144, kInvalidArgument, "a Seurat headbox has zero extent")                  \
  X(kSeuratViewGroup, 145, kCorrupt, "a Seurat view group is not one 360-degree viewpoint")     \
  X(kSeuratChannel, 146, kCorrupt, "a channel a Seurat view names is missing from its image")   \
  X(kSeuratImageSize, 147, kCorrupt, "Seurat colour and depth images differ in size")           \
  X(kSeuratDepth, 148, kCorrupt, "a Seurat depth pixel lies outside its camera's frustum")      \
  X(kEquirectInput, 149, kCorrupt, "an equirectangular input is malformed")                     \
  /* scene files: 150-169 (format/SCENE.md) */                                                  \
  X(kSceneFileSyntax, 150, kCorrupt, "a scene manifest is not valid JSON")                      \
  X(kSceneFileVersion, 151, kUnsupported, "a scene manifest has an unknown format or version")  \
  X(kSceneFileField, 152, kCorrupt, "a scene field is missing, mistyped or inconsistent")       \
  X(kSceneFilePath, 153, kCorrupt, "a scene path is absolute, holds '..' or leaves its folder") \
  X(kSceneFileMissing, 154, kIo, "a buffer or texture named by a scene is missing")             \
  X(kSceneFileBufferSize, 155, kNeedMoreData, "a scene buffer's size is not as declared")       \
  X(kSceneFileView, 156, kCorrupt, "a buffer view is misaligned, outside or overlapping")       \
  X(kSceneFileValue, 157, kCorrupt, "a scene value is NaN, infinite or outside its range")      \
  X(kSceneFileIndex, 158, kCorrupt, "a vertex, mesh, material or texture index is invalid")     \
  X(kSceneFileTexture, 159, kCorrupt, "a scene texture cannot be decoded or is too large")      \
  X(kSceneFileLimit, 160, kLimit, "a scene exceeds a documented size limit")                    \
  X(kSceneFileWriterMisuse, 161, kInvalidArgument, "the scene writer got mismatched array sizes")\
  /* sharded capture and encode: 162-168 (docs/FARM.md) */                                      \
  X(kShardFile, 162, kCorrupt, "a file is not an analysis or shard file, or its record is bad")  \
  X(kShardMismatch, 163, kInvalidArgument, "shards come from different analyses or captures")   \
  X(kShardOverlap, 164, kInvalidArgument, "two shards hold the same view or frame")              \
  X(kShardMissing, 165, kInvalidArgument, "a view or frame is in no shard")                      \
  X(kShardRange, 166, kInvalidArgument, "a shard's views or frames are outside the set")         \
  /* coverage unmixing: 169 (calf/capture/coverage_unmix.h) */                                 \
  X(kCoverageUnmixInput, 169, kInvalidArgument, "faces or options given to unmixing are unusable")\
  /* calf-capture: 170-199 */                                                                   \
  X(kSceneUnknown, 170, kInvalidArgument, "no built-in scene has that name")                    \
  X(kSceneLoad, 171, kCorrupt, "a scene file could not be imported")                            \
  X(kSceneFormat, 172, kUnsupported, "a scene file's format is not supported")                  \
  X(kSceneEmpty, 173, kInvalidArgument, "a scene has no renderable geometry")                   \
  X(kSceneGeometry, 174, kCorrupt, "a scene holds non-finite or degenerate geometry")           \
  X(kRigSyntax, 175, kInvalidArgument, "a rig description cannot be parsed")                    \
  X(kViewpointInsideGeometry, 176, kInvalidArgument, "a viewpoint or eye lies inside geometry") \
  X(kCaptureOption, 177, kInvalidArgument, "a render option is outside its range")              \
  X(kRayTracer, 178, kInternal, "Embree failed to create a device or scene")                    \
  /* surfel candidates: 180-189 (format/SURFEL_CANDIDATES.md, calf-capture --surfel-candidates) */ \
  X(kSurfelFileIdentifier, 180, kCorrupt, "a file is not a surfel-candidate file")              \
  X(kSurfelFileVersion, 181, kUnsupported, "a surfel-candidate file's version or flag is unknown") \
  X(kSurfelFileTruncated, 182, kNeedMoreData, "a surfel-candidate file ends inside a record")   \
  X(kSurfelFileField, 183, kCorrupt, "a surfel-candidate field contradicts the file or record") \
  X(kSurfelFileValue, 184, kCorrupt, "a surfel candidate value is NaN, infinite or out of range") \
  X(kSurfelFileLimit, 185, kLimit, "a surfel-candidate count exceeds its documented limit")     \
  X(kSurfelFileHash, 186, kCorrupt, "a surfel-candidate record's hash does not match")          \
  X(kSurfelWriterMisuse, 187, kInvalidArgument, "the candidate writer got inconsistent arrays") \
  X(kSurfelOption, 188, kInvalidArgument, "a surfel-candidate option is outside its range")     \
  X(kSurfelSceneMismatch, 189, kInvalidArgument, "surfel candidates do not belong to the scene") \
  /* model textures: 190-194 */                                                                \
  X(kModelTextureMissing, 190, kIo, "a texture a model's material references is missing")       \
  X(kModelTexture, 191, kCorrupt, "a model's texture cannot be decoded or is too large")         \
  /* camera placement: 195-198 (calf-capture --rig auto / hammersley) */                        \
  X(kPlacementSyntax, 195, kInvalidArgument, "an auto / hammersley rig cannot be parsed")       \
  X(kPlacementVolume, 196, kInvalidArgument, "no usable viewpoint in the placement volume")     \
  /* encoder: 200-299 */                                                                        \
  X(kEncoderOption, 200, kInvalidArgument, "an encoder option is outside its range")          \
  X(kEncoderInput, 201, kCorrupt, "the capture set contradicts itself or the chosen options")  \
  X(kLightfieldChunk, 202, kCorrupt, "a lightfield chunk is missing or contradicts its layout") \
  X(kLightfieldFormat, 203, kUnsupported, "a lightfield track uses a format the decoder lacks") \
  X(kTilesChunk, 210, kCorrupt, "a tiles chunk is missing, repeated or contradicts its layout") \
  X(kTilesUnsupported, 211, kUnsupported, "a tiles track's layout, format, flag or frame count is unknown") \
  X(kTilesValue, 212, kCorrupt, "a tiles value is NaN, infinite or outside its range")        \
  X(kTilesLimit, 213, kLimit, "a tiles track count or chunk size exceeds its limit")          \
  X(kTilesInput, 214, kInvalidArgument, "a tile set given to the encoder is inconsistent")    \
  X(kMeshChunk, 220, kCorrupt, "a mesh chunk is missing, repeated or contradicts its layout")  \
  X(kMeshUnsupported, 221, kUnsupported, "a mesh track's layout version or flag is unknown")    \
  X(kMeshIndex, 222, kCorrupt, "a mesh vertex, triangle, prototype or material index is invalid") \
  X(kMeshValue, 223, kCorrupt, "a mesh value is NaN, infinite or outside its range")            \
  X(kMeshLimit, 224, kLimit, "a mesh track count or chunk size exceeds its limit")              \
  X(kSurfelsChunk, 230, kCorrupt, "a surfels chunk is missing, repeated or contradicts its layout") \
  X(kSurfelsUnsupported, 231, kUnsupported, "a surfels track's layout version or flag is unknown") \
  X(kSurfelsPairing, 232, kCorrupt, "a surfels track and its mesh track do not pair")        \
  X(kSurfelsValue, 233, kCorrupt, "a surfels value is NaN, infinite or outside its range")    \
  X(kSurfelsLimit, 234, kLimit, "a surfels track count or chunk size exceeds its limit")      \
  X(kSurfelsInput, 235, kInvalidArgument, "surfels given to the encoder are inconsistent")    \
  X(kSurfelNoCandidates, 240, kInvalidArgument, "no candidate surfel position was given")   \
  X(kSurfelCount, 241, kInvalidArgument, "a surfel count is zero or above the candidates")  \
  X(kSurfelPosition, 242, kInvalidArgument, "a candidate surfel position is not finite")    \
  X(kSurfelSamplerOption, 243, kInvalidArgument, "a surfel sampler option is outside its range")   \
  X(kSurfelRadius, 244, kInvalidArgument, "a surfel radius, r_m or p_m is invalid")         \
  /* tiles builder: 250-256 (docs/TILES.md) */                                                  \
  X(kTilesOption, 250, kInvalidArgument, "a tiles build option is outside its range")           \
  X(kTilesFrame, 251, kInvalidArgument, "the frame to build tiles from is not in the capture set") \
  X(kTilesEmpty, 252, kInvalidArgument, "the capture frame has no view or no finite depth")     \
  X(kTilesBudget, 253, kInvalidArgument, "the tile budget cannot cover the view region")        \
  X(kTilesAtlas, 254, kLimit, "the tile textures do not fit the largest atlas")                 \
  X(kEncoderCoverage, 255, kCorrupt, "capture coverage is not whole 1/16 cells of its mask")     \
  X(kEncoderAv1, 256, kInternal, "the AV1 encoder (SVT-AV1 or libaom) failed")                  \
  X(kEncoderAv1Input, 257, kInvalidArgument, "reserved (HDR input is coded as av1hdr)")                    \
  /* decoder: 300-399 */                                                                        \
  X(kDecoderArgument, 300, kInvalidArgument, "a decoder option, frame, view or eye is invalid") \
  X(kAv1Decode, 301, kCorrupt, "an AV1 colour stream does not decode")                         \
  X(kAv1Picture, 302, kCorrupt, "a decoded AV1 picture is not the cell's frame of the track's bit depth and subsampling")\
  /* player: 400-499 */                                                                         \
  X(kPlayerViewSet, 400, kInvalidArgument, "a view's face size or position is invalid")         \
  X(kPlayerRect, 401, kInvalidArgument, "a texture update rect or its source buffer is invalid") \
  X(kPlayerNoMaterial, 402, kInvalidArgument, "material written to a view without material")    \
  X(kPlayerOptions, 403, kInvalidArgument, "a render option or the eye is outside its range")   \
  X(kPlayerGl, 404, kUnsupported, "an OpenGL context or a required GL feature is missing")    \
  X(kPlayerGlLayout, 410, kInvalidArgument, "a GL texture layout cannot be held")           \
  X(kPlayerGlUpdate, 411, kInvalidArgument, "a texture update does not fit the GL textures")  \
  X(kPlayerGlCall, 412, kInternal, "a GL call reported an error")                             \
  X(kPlayerCaptureViews, 430, kInvalidArgument, "a capture view-frame cannot become player views") \
  X(kImageCompare, 431, kInvalidArgument, "images to compare are empty, unequal or too small") \
  X(kImageCompareOption, 432, kInvalidArgument, "an image metric or heat-map option is invalid") \
  X(kViewSelectOptions, 450, kInvalidArgument, "a view-selection option is out of range")       \
  X(kViewSelectViewpoint, 451, kInvalidArgument, "a viewpoint position is not finite")         \
  X(kViewSelectEye, 452, kInvalidArgument, "the eye pose given to view selection is invalid")  \
  X(kViewSelectFrameTime, 453, kInvalidArgument, "a frame time is negative or not finite")     \
  X(kViewSelectLimit, 454, kLimit, "more viewpoints than view selection accepts")              \
  X(kPlaybackClip, 460, kInvalidArgument, "the file has nothing calf-play can play")            \
  X(kPlaybackOption, 461, kInvalidArgument, "a calf-play option or eye path is unusable")        \
  X(kMeshDrawList, 470, kInvalidArgument, "a mesh draw list is inconsistent or not finite")    \
  X(kMeshRenderOptions, 471, kInvalidArgument, "a mesh render option is outside its range")    \
  X(kMeshGlStructure, 472, kInvalidArgument, "a mesh draw list differs from its GL upload")    \
  X(kMeshPlayback, 473, kInvalidArgument, "a mesh track cannot be played as asked")           \
  X(kSurfelDrawList, 474, kInvalidArgument, "a surfel draw list is inconsistent or not finite") \
  X(kSurfelRenderOptions, 475, kInvalidArgument, "a surfel render option is outside its range") \
  X(kSurfelGlStructure, 476, kInvalidArgument, "a surfel draw list differs from its GL upload") \
  X(kTilesDraw, 477, kInvalidArgument, "a tile set cannot be drawn or played as asked")       \
  X(kTilesRenderOptions, 478, kInvalidArgument, "a tiles render option is outside its range")  \
  X(kExportInput, 480, kInvalidArgument, "a track cannot be exported as asked")                \
  X(kExportWrite, 481, kInternal, "the glTF / OBJ exporter failed")                             \
  X(kExportTilesOption, 482, kInvalidArgument, "a tiles export option is outside its range")  \
  X(kExportTilesEmpty, 483, kInvalidArgument, "a tile set to export has no tile or no atlas")  \
  X(kExportWebFolder, 484, kInvalidArgument, "a web folder to write exists and is not empty")  \
  X(kExportWebFiles, 485, kIo, "the web player's files to copy are not found")                 \
  /* end of the list: every line above ends with a backslash */
// clang-format on

enum class ErrorId : uint16_t {
  kOk = 0,
#define CALF_ERROR_ENUM(name, number, kind, summary) name = number,
  CALF_ERROR_LIST(CALF_ERROR_ENUM)
#undef CALF_ERROR_ENUM
};

// The kind an id belongs to (kInternal for an id not in the list).
ErrorKind error_kind(ErrorId id);
// The one-line summary of an id ("" for kOk or an unknown id).
const char* error_summary(ErrorId id);

}  // namespace calf
