// shared/draw.h compiled as C++: the sampler's draw of one sample, the
// same arithmetic a device repeats (shaders/judge/sample.comp).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>

#include <glm/glm.hpp>

#include "shared/compat.h"

namespace depthbench::draw {
using real = float;  // (random.h's random_unit, unused here)
using uint = std::uint32_t;
using dvec3 = glm::dvec3;
using dmat3 = glm::dmat3;
using std::floor;
using std::max;
using std::min;
// draw.h needs random.h first.
// clang-format off
#include "shared/random.h"
#include "shared/draw.h"
// clang-format on
}  // namespace depthbench::draw
