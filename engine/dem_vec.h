// SPDX-License-Identifier: MIT
/// @file dem_vec.h
/// Small 3-vector arithmetic used by every kernel. All inline: the contact
/// kernels are specialised by the compiler, so these must fold away.
#ifndef DEM_VEC_H
#define DEM_VEC_H

#include <math.h>

/// π (M_PI is not in strict C11): the one definition, used by every folder
/// (the independent reference, tests/support/ref_two_particles.c, keeps its own).
#define DEM_PI 3.14159265358979323846

/// Force inlining of a hot kernel that the compiler's size heuristics would
/// otherwise leave as a call (the contact law inside the pair loop).
/// DEM_NO_FORCED_INLINE (the sanitizer build, CMakeLists.txt) leaves the
/// choice to the compiler: forced into every one of dem_pairs.c's pair loops
/// and instrumented, the kernel made that one file take minutes of CPU to
/// compile. Inlining changes no arithmetic, only where the code sits.
#if (defined(__GNUC__) || defined(__clang__)) && !defined(DEM_NO_FORCED_INLINE)
#define DEM_ALWAYS_INLINE inline __attribute__((always_inline))
#else
#define DEM_ALWAYS_INLINE inline
#endif

/// A 3-vector of doubles; plain struct so arrays of it are dense (24 bytes).
typedef struct dem_vec3 {
    double x, y, z;
} dem_vec3;

static inline dem_vec3 dem_v3(double x, double y, double z) { return (dem_vec3){x, y, z}; }
static inline dem_vec3 dem_v3_add(dem_vec3 a, dem_vec3 b) { return dem_v3(a.x + b.x, a.y + b.y, a.z + b.z); }
static inline dem_vec3 dem_v3_sub(dem_vec3 a, dem_vec3 b) { return dem_v3(a.x - b.x, a.y - b.y, a.z - b.z); }
static inline dem_vec3 dem_v3_scale(dem_vec3 a, double s) { return dem_v3(a.x * s, a.y * s, a.z * s); }
static inline dem_vec3 dem_v3_axpy(double s, dem_vec3 a, dem_vec3 b) { return dem_v3(s * a.x + b.x, s * a.y + b.y, s * a.z + b.z); }
static inline double dem_v3_dot(dem_vec3 a, dem_vec3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
static inline double dem_v3_norm2(dem_vec3 a) { return dem_v3_dot(a, a); }
static inline double dem_v3_norm(dem_vec3 a) { return sqrt(dem_v3_dot(a, a)); }
static inline dem_vec3 dem_v3_cross(dem_vec3 a, dem_vec3 b)
{
    return dem_v3(a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x);
}
/// Component a (0 x, 1 y, 2 z).
static inline double dem_v3_comp(dem_vec3 v, int a) { return a == 0 ? v.x : a == 1 ? v.y : v.z; }
/// Whether p lies in the box [lo, hi] (boundaries included; NaN never does).
static inline int dem_v3_in_box(dem_vec3 p, dem_vec3 lo, dem_vec3 hi)
{
    return p.x >= lo.x && p.x <= hi.x && p.y >= lo.y && p.y <= hi.y && p.z >= lo.z && p.z <= hi.z;
}
static inline dem_vec3 dem_v3_neg(dem_vec3 a) { return dem_v3(-a.x, -a.y, -a.z); }
static inline int dem_v3_isfinite(dem_vec3 a) { return isfinite(a.x) && isfinite(a.y) && isfinite(a.z); }

#endif
