// bodypoint: W trajectories in lockstep in the lanes of one vector register (issue #14).
//
// For sweeps whose members share the method, the step and the number of steps: the fixed-step
// Lie-Poisson and thesis families and RK4, one Coulomb centre at the origin (every thesis scene),
// B != 0 (the spin kernels). Each lane computes exactly the bits of the scalar `run` with
// invariants tracked (tests/lib/test_batch.cpp asserts equality), so a batch is a faster way to the same
// numbers, not an approximation. The width is the widest the CPU runs among those the compiler
// built: 8 (AVX-512), 4 (AVX2), 2 (SSE2); BODYPOINT_SIMD=2|4|8 narrows it (for measurements).
// A lane that diverges computes NaN in its own lane only; all lanes take the same number of steps.
#pragma once

#include "bodypoint/model.hpp"
#include "bodypoint/run.hpp"
#include "bodypoint/detail/run_parts.hpp"

#include <atomic>
#include <cstddef>
#include <vector>

namespace bodypoint::batch {

/// Lanes per batch on this machine, and the instruction set ("avx512", "avx2", "sse2").
std::size_t width();
const char* isa();
/// Every width this CPU runs, widest first (the tests run each).
std::vector<std::size_t> widths();

/// One trajectory of a batch: the body, its start and the strength of the centre at the origin.
struct Member {
  BodyPoint p;
  State s0;
  double A = 0.0;
};

/// True when `method` has a batch kernel and the scene fits one: one Coulomb centre at the origin
/// and B != 0.
bool accepts(const MethodInfo& method, const Body& body, const std::vector<Centre>& centres);

/// Runs up to width() members (or, given, `lanes` of widths()) for spec.steps fixed steps of spec.h with
/// invariants tracked; one result per member, as `run` returns it (wall_s: the batch's time shared
/// equally). Throws Error when the method has no batch kernel or there are too many members; returns
/// no result (an empty vector) when `cancel`, polled every kPollStride steps as the scalar loops poll
/// it, is set.
std::vector<RunResult> run(const MethodInfo& method, const std::vector<Member>& members, const FixedSteps& spec,
                           std::size_t lanes = 0, const std::atomic<bool>* cancel = nullptr);

}  // namespace bodypoint::batch
