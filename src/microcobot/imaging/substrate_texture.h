#pragma once
/// @file
/// The substrate's procedural surface texture: value noise (a lattice of seeded random values,
/// interpolated) in octaves fixed to the stage, so the same seed shows the same surface at every
/// magnification. Octaves finer than the pixel are replaced by their pixel average: independent
/// values per pixel whose rms shrinks with the number of lattice cells a pixel averages
/// ((grain / pixel) in each direction).

#include "microcobot/imaging/scene_snapshot.h"

namespace mc::imaging {

/// Relative texture at stage point (x, y), seen by pixels of size `pixel_m`: zero mean, rms
/// about `substrate.texture_contrast` (for octaves coarser than the pixel). Pure function.
double substrate_texture(const Substrate& substrate, double x_m, double y_m, double pixel_m) noexcept;

}  // namespace mc::imaging
