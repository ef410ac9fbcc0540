// SPDX-License-Identifier: Apache-2.0
// The octree's internal header for its tests. Marked a system header because its
// vectorisation pragmas are meant for the proximity target (-fopenmp-simd) and GCC 12 cannot
// silence -Wunknown-pragmas otherwise. Tests should only call functions the library compiles
// (Octree, prepare_bounds): the inline distance code belongs to the library's flags
// (-ffp-contract=off).
#pragma once
#pragma GCC system_header

#include "src/proximity/brute.hpp"
#include "src/proximity/octree.hpp"
