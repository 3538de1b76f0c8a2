// The sample points of calf-capture's converged rendering (docs/RENDERING.md "Converged
// capture"): sub-pixel positions and ambient-occlusion directions come from one base-2
// (0, 2)-sequence, digit-scrambled per pixel.
//
// Point i is (radical inverse of i in base 2, Sobol's second coordinate of i). Every aligned block
// of 2^m consecutive points, so every prefix of 2^m points, is a (0, m, 2)-net: each cell of any
// 2^a x 2^b grid over [0, 1)^2 with a + b = m holds exactly one point (16 points: one per cell of
// the 4 x 4, 2 x 8, 8 x 2, 1 x 16 and 16 x 1 grids). XOR-ing each coordinate's binary digits with
// a scramble keeps that property and makes the points of different pixels (different scrambles)
// independent, so the error of a pixel's mean is unbiased noise rather than a pattern. Growing the
// sample count by doubling keeps every stage a net, which the adaptive rounds of the tracer use.
#pragma once

#include <cstdint>

namespace calf::samples {

struct SamplePoint {
  float x = 0, y = 0;  // each in [0, 1), multiples of 2^-24
};

// Point `index` of the (0, 2)-sequence with the digit scrambles `scramble_x`, `scramble_y` (the
// binary digits of each coordinate, most significant first, are XOR-ed with the scramble's bits
// from bit 31 down).
SamplePoint scrambled_sequence_point(uint32_t index, uint32_t scramble_x, uint32_t scramble_y);

}  // namespace calf::samples
