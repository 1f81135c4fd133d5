#pragma once
// Umbrella header, for convenience only: every infolerp header compiles on its own.
#include "infolerp/core/executor.hpp"
#include "infolerp/core/mesh_traits.hpp"
#include "infolerp/core/status.hpp"
#include "infolerp/core/tracer.hpp"
#include "infolerp/mesh/adaptors.hpp"
#include "infolerp/mesh/topology.hpp"
#include "infolerp/mesh/geometry.hpp"
#include "infolerp/mesh/validate.hpp"
#include "infolerp/info/entropy.hpp"
#include "infolerp/info/jensen_shannon.hpp"
#include "infolerp/info/log2.hpp"
