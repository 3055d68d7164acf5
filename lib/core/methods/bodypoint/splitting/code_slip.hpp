// bodypoint: the index slip of the thesis's published code, reproduced on request (thesis.hpp).
#pragma once

namespace bodypoint::splitting {

/// The thesis's published Java code (github.com/axothy/Body-point-dynamics) has an index slip in its
/// third kick: RuthMethodForSystem and YoshidaMethodForSystem (Forest-Ruth 4) give the z-component of
/// the third velocity kick the force at the first stage's position, r_first, instead of r_third;
/// YoshidaMethod6thOrder does the same for the z-component of the third spin kick as well. It is
/// reproduced only under ForceLaw::thesis_code (model.hpp), to regenerate the figures as published.
enum class CodeSlip { none, third_v_z, third_vw_z };

}  // namespace bodypoint::splitting
