/*
 * tinybvh's BVH8_CPU (Bikker; header-only, https://github.com/jbikker/tinybvh)
 * behind a C interface, for bench/vs_tinybvh.c only: the comparison of
 * frusta's single rays with the fastest single-ray tracer there is. Built
 * by bench/vs_tinybvh.sh against a tinybvh checkout the user names; none
 * of tinybvh's code is in this repository.
 */
#define TINYBVH_IMPLEMENTATION
#include "tiny_bvh.h"
#include <omp.h>
#include <stdint.h>
#include <vector>

extern "C" {

/* BVH8_CPU over nt triangles of xyz vertices: its high-quality build, or
 * (optimize > 0) its quick build refined by that many rounds of its
 * optimizer, as tinybvh's speed test makes them. */
void *tbs_build(const float *xyz, const uint32_t *idx, size_t nt, int optimize) {
  std::vector<tinybvh::bvhvec4> tri(3 * nt);
  for (size_t i = 0; i < 3 * nt; i++) {
    const float *p = xyz + 3 * (size_t)idx[i];
    tri[i] = tinybvh::bvhvec4(p[0], p[1], p[2], 0.0f);
  }
  tinybvh::BVH8_CPU *b = new tinybvh::BVH8_CPU();
  if (optimize > 0) {
    b->Build(tri.data(), (uint32_t)nt);
    b->Optimize((uint32_t)optimize, true);
  } else {
    b->BuildHQ(tri.data(), (uint32_t)nt);
  }
  return b;
}

void tbs_release(void *b) { delete (tinybvh::BVH8_CPU *)b; }

/* Rays as origin (3), unit direction (3) and tfar, 7 floats each; closest
 * hits' t (inf on a miss) and triangle, or occlusion, on threads threads. */
void tbs_intersect(const void *bvh, const float *rays, size_t n, float *t, uint32_t *prim, int threads) {
  const tinybvh::BVH8_CPU *b = (const tinybvh::BVH8_CPU *)bvh;
#pragma omp parallel for schedule(dynamic, 1024) num_threads(threads)
  for (long long i = 0; i < (long long)n; i++) {
    const float *r = rays + 7 * i;
    tinybvh::Ray ray(tinybvh::bvhvec3(r[0], r[1], r[2]), tinybvh::bvhvec3(r[3], r[4], r[5]), r[6]);
    b->Intersect(ray);
    const int hit = ray.hit.t < r[6];
    t[i] = hit ? ray.hit.t : INFINITY;
    prim[i] = hit ? ray.hit.prim : 0xffffffffu;
  }
}

void tbs_occluded(const void *bvh, const float *rays, size_t n, uint8_t *occ, int threads) {
  const tinybvh::BVH8_CPU *b = (const tinybvh::BVH8_CPU *)bvh;
#pragma omp parallel for schedule(dynamic, 1024) num_threads(threads)
  for (long long i = 0; i < (long long)n; i++) {
    const float *r = rays + 7 * i;
    const tinybvh::Ray ray(tinybvh::bvhvec3(r[0], r[1], r[2]), tinybvh::bvhvec3(r[3], r[4], r[5]), r[6]);
    occ[i] = b->IsOccluded(ray);
  }
}
}
