// Procedural textures (CV_8UC3 BGR) for surfaces without a photograph: plaster, carpet, wood,
// cardboard, ceiling tiles, book spines, keyboards, cloth. All are deterministic functions of
// their arguments and the given generator. Thread-compatible (the cv::RNG is the caller's).
#pragma once

#include <opencv2/core.hpp>

namespace dynorb::synth {

// Fractal value noise in [0,1] (CV_32F): octaves of smoothly interpolated random grids, the
// coarsest with cells of `cell_px` texels.
cv::Mat FractalNoise(cv::Size size, double cell_px, int octaves, cv::RNG& rng);

// Uniform colour modulated by fractal noise of relative amplitude `amplitude` plus fine grain.
cv::Mat NoisyColor(cv::Size size, cv::Scalar bgr, double amplitude, double cell_px, cv::RNG& rng);
cv::Mat Carpet(cv::Size size, cv::Scalar bgr, cv::RNG& rng);
cv::Mat Wood(cv::Size size, cv::Scalar bgr, cv::RNG& rng);
cv::Mat Cardboard(cv::Size size, cv::RNG& rng);
// Ceiling of 0.6 m tiles with light panels; `px_per_m` texels per metre.
cv::Mat CeilingTiles(cv::Size size, double px_per_m, cv::RNG& rng);
cv::Mat BookSpines(cv::Size size, cv::RNG& rng);
cv::Mat Keyboard(cv::Size size, cv::RNG& rng);
cv::Mat Plaid(cv::Size size, cv::Scalar bgr, cv::RNG& rng);
cv::Mat Denim(cv::Size size, cv::Scalar bgr, cv::RNG& rng);
// Scribbles and text-like strokes on a light background (whiteboards, notes, posters).
cv::Mat Scribbles(cv::Size size, cv::Scalar background, cv::RNG& rng);
// A stand-in "photograph" for a missing picture: coloured shapes on a noisy background.
cv::Mat PseudoPhoto(cv::Size size, cv::RNG& rng);

}  // namespace dynorb::synth
