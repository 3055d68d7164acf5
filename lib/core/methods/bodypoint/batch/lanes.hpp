// bodypoint: W doubles in one vector register (GCC/Clang vector extensions), and 3-vectors of them.
//
// Compiled once per width (batch_w.cpp with BODYPOINT_BATCH_W = 2, 4 or 8 and the matching -m flags),
// inside a namespace of that width. Every operation is the IEEE operation of the scalar code, lane by
// lane, in the scalar code's order (Eigen's for 3-vectors: (x0 + x1) + x2 in reductions, measured), and the
// translation units are built with -ffp-contract=off, so no multiply-add is fused where the scalar
// code rounds twice: a lane computes the same bits as the scalar path.
#pragma once

#include <cmath>
#include <cstddef>
#if defined(__x86_64__)
#include <immintrin.h>
#endif

#ifndef BODYPOINT_BATCH_W
#error "lanes.hpp is compiled with BODYPOINT_BATCH_W set (batch_w.cpp)"
#endif

namespace bodypoint::batch::BODYPOINT_BATCH_NS {

inline constexpr std::size_t W = BODYPOINT_BATCH_W;
using Lane = double __attribute__((vector_size(8 * W)));

inline Lane splat(double x) {
  Lane v;
  for (std::size_t i = 0; i < W; ++i) v[i] = x;
  return v;
}

inline Lane vsqrt(Lane x) {
#if !defined(__x86_64__)
  for (std::size_t i = 0; i < W; ++i) x[i] = __builtin_sqrt(x[i]);
  return x;
#elif BODYPOINT_BATCH_W == 8
  // The zero-masked form: GCC 12 warns that _mm512_sqrt_pd's undefined pass-through is uninitialised.
  return reinterpret_cast<Lane>(_mm512_maskz_sqrt_pd(0xFF, reinterpret_cast<__m512d>(x)));
#elif BODYPOINT_BATCH_W == 4
  return reinterpret_cast<Lane>(_mm256_sqrt_pd(reinterpret_cast<__m256d>(x)));
#else
  return reinterpret_cast<Lane>(_mm_sqrt_pd(reinterpret_cast<__m128d>(x)));
#endif
}

inline Lane vabs(Lane x) { return x < 0.0 ? -x : x; }
template <class M>
inline bool all(M m) {
  for (std::size_t i = 0; i < W; ++i)
    if (!m[i]) return false;
  return true;
}

struct V3 {
  Lane x, y, z;
};
inline V3 operator+(const V3& a, const V3& b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
inline V3 operator-(const V3& a, const V3& b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
inline V3 operator*(Lane s, const V3& a) { return {s * a.x, s * a.y, s * a.z}; }
inline V3 operator*(const V3& a, Lane s) { return {a.x * s, a.y * s, a.z * s}; }
inline V3& operator+=(V3& a, const V3& b) { return a = a + b; }
inline V3 cross(const V3& a, const V3& b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
/// Eigen's order for a fixed 3-vector (SSE2 packet of the first two, then the third):
/// (x0 y0 + x1 y1) + x2 y2.
inline Lane dot(const V3& a, const V3& b) { return (a.x * b.x + a.y * b.y) + a.z * b.z; }
inline Lane squared_norm(const V3& a) { return dot(a, a); }

/// x += dx with Kahan compensation, as splitting::compensated_add.
inline void compensated_add(V3& x, V3& err, const V3& dx) {
  const V3 y = dx - err;
  const V3 t = x + y;
  err = (t - x) - y;
  x = t;
}

}  // namespace bodypoint::batch::BODYPOINT_BATCH_NS
