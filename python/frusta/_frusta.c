/*
 * frusta._frusta: the CPython extension under the frusta package, over the
 * public C API alone (frusta.h).
 *
 * Arrays in: any float dtype of shape (..., 3); a C-contiguous float32 one is
 * read in place, others are converted once. Arrays out: new numpy arrays of
 * the rays' leading shape. Tracing runs without the GIL on OpenMP threads,
 * in chunks of CHUNK rays packed into fr_ray records on the thread's stack.
 * A scene counts the calls tracing it, so that close() cannot free it under
 * them.
 */
#define PY_SSIZE_T_CLEAN
#include <Python.h>
#define NPY_NO_DEPRECATED_API NPY_1_7_API_VERSION
#include <numpy/arrayobject.h>
#include <limits.h>
#include <math.h>
#include <omp.h>
#include <stdlib.h>
#include <string.h>
#include "frusta.h"

#define CHUNK 1024
#define GATHER_AHEAD 16 /* rays packed in an order fetch this many ahead */

static int n_threads; /* 0: OpenMP's default */

/* ---- errors ------------------------------------------------------------------ */

static PyObject *raise_fr(fr_error e, const char *msg) {
  PyObject *type = PyExc_RuntimeError;
  switch (e) {
  case FR_ERR_ARG: case FR_ERR_FORMAT: type = PyExc_ValueError; break;
  case FR_ERR_IO: type = PyExc_OSError; break;
  case FR_ERR_NOMEM: type = PyExc_MemoryError; break;
  case FR_ERR_UNSUPPORTED: type = PyExc_NotImplementedError; break;
  default: break;
  }
  PyErr_SetString(type, msg && *msg ? msg : fr_error_name(e));
  return NULL;
}

/* ---- the Scene type ------------------------------------------------------------ */

typedef struct {
  PyObject_HEAD
  fr_scene *scene;
  int busy; /* calls tracing it now (changed with the GIL held) */
  /* the arrays a scene made from numpy arrays reads in place (the
   * vertices as given where they are C-contiguous float32, else a copy;
   * the triangles always its own checked copy); held until the scene is
   * released */
  PyObject *shared_vertices, *shared_triangles;
} SceneObject;

static PyTypeObject SceneType;

static int scene_open(SceneObject *s) {
  if (s->scene) return 1;
  PyErr_SetString(PyExc_ValueError, "the scene is closed");
  return 0;
}

/* Smooth shading normals (for rendering; crease in degrees, 0: none), then
 * the commit. */
static PyObject *wrap_scene(PyTypeObject *type, fr_scene *sc, float smooth) {
  if (!(smooth >= 0.0f && smooth <= 180.0f)) {
    fr_scene_release(sc);
    return PyErr_Format(PyExc_ValueError, "smooth: %g is not in 0..180 degrees", (double)smooth);
  }
  fr_error e = smooth > 0.0f ? fr_scene_smooth(sc, smooth) : FR_OK;
  if (!e) e = fr_scene_commit(sc);
  if (e != FR_OK) {
    raise_fr(e, fr_last_error());
    fr_scene_release(sc);
    return NULL;
  }
  SceneObject *o = (SceneObject *)type->tp_alloc(type, 0);
  if (!o) { fr_scene_release(sc); return NULL; }
  o->scene = sc;
  return (PyObject *)o;
}

/* The scene, then the arrays it read in place. */
static void scene_release(SceneObject *s) {
  if (s->scene) fr_scene_release(s->scene);
  s->scene = NULL;
  Py_CLEAR(s->shared_vertices);
  Py_CLEAR(s->shared_triangles);
}

/* A float array of shape (..., 3) as C-contiguous float32 (in place if it
 * is one). */
static PyArrayObject *vec3_array(PyObject *obj, const char *name) {
  PyArrayObject *a = (PyArrayObject *)PyArray_FROM_O(obj);
  if (!a) return NULL;
  if (!PyArray_ISFLOAT(a)) {
    PyObject *d = PyObject_Str((PyObject *)PyArray_DESCR(a));
    if (d) {
      PyErr_Format(PyExc_TypeError, "%s: expected a float array, got dtype %U", name, d);
      Py_DECREF(d);
    }
    Py_DECREF(a);
    return NULL;
  }
  if (PyArray_NDIM(a) < 1 || PyArray_DIM(a, PyArray_NDIM(a) - 1) != 3) {
    PyErr_Format(PyExc_ValueError, "%s: expected shape (..., 3), got %d dimensions ending in %zd", name,
                 PyArray_NDIM(a), PyArray_NDIM(a) ? (Py_ssize_t)PyArray_DIM(a, PyArray_NDIM(a) - 1) : (Py_ssize_t)0);
    Py_DECREF(a);
    return NULL;
  }
  PyArrayObject *f = (PyArrayObject *)PyArray_FROM_OTF((PyObject *)a, NPY_FLOAT32, NPY_ARRAY_IN_ARRAY | NPY_ARRAY_FORCECAST);
  Py_DECREF(a);
  return f;
}

/* Triangles as the scene's own C-contiguous uint32 (n, 3) array, every
 * index checked to be below nv. Always a copy: a caller who changed an
 * index afterwards would otherwise send the scene's lookups out of its
 * vertex array. */
static PyArrayObject *triangle_array(PyObject *obj, size_t nv) {
  PyArrayObject *ta = (PyArrayObject *)PyArray_FROM_O(obj);
  if (!ta) return NULL;
  if (!PyArray_ISINTEGER(ta) || PyArray_NDIM(ta) != 2 || PyArray_DIM(ta, 1) != 3) {
    PyErr_SetString(PyExc_ValueError, "triangles: expected an integer array of shape (n, 3)");
    Py_DECREF(ta);
    return NULL;
  }
  /* checked at their own width (as int64), so no value wraps into range */
  PyArrayObject *t = (PyArrayObject *)PyArray_FROM_OTF((PyObject *)ta, NPY_INT64, NPY_ARRAY_IN_ARRAY);
  if (!t) { Py_DECREF(ta); return NULL; }
  const size_t n = (size_t)PyArray_SIZE(t);
  const int64_t *ti = PyArray_DATA(t);
  for (size_t i = 0; i < n; i++)
    if (ti[i] < 0 || (uint64_t)ti[i] >= nv) {
      PyErr_Format(PyExc_ValueError, "triangles: triangle %zu names vertex %lld of %zu", i / 3, (long long)ti[i], nv);
      Py_DECREF(t);
      Py_DECREF(ta);
      return NULL;
    }
  PyArrayObject *u = (PyArrayObject *)PyArray_FROM_OTF((PyObject *)t, NPY_UINT32,
                                                       NPY_ARRAY_IN_ARRAY | NPY_ARRAY_FORCECAST | NPY_ARRAY_ENSURECOPY);
  Py_DECREF(t);
  Py_DECREF(ta);
  return u;
}

static PyObject *scene_new(PyTypeObject *type, PyObject *args, PyObject *kw) {
  static char *names[] = {"vertices", "triangles", "smooth", NULL};
  PyObject *vo, *to;
  float smooth = 0.0f;
  if (!PyArg_ParseTupleAndKeywords(args, kw, "OO|f", names, &vo, &to, &smooth)) return NULL;
  PyArrayObject *v = vec3_array(vo, "vertices");
  if (!v) return NULL;
  const size_t nv = (size_t)(PyArray_SIZE(v) / 3);
  PyArrayObject *t = triangle_array(to, nv);
  if (!t) { Py_DECREF(v); return NULL; }
  const size_t nt = (size_t)PyArray_DIM(t, 0);
  const float *pos = PyArray_DATA(v);
  for (size_t i = 0; i < 3 * nv; i++)
    if (!isfinite(pos[i])) {
      Py_DECREF(v);
      Py_DECREF(t);
      return PyErr_Format(PyExc_ValueError, "vertices: vertex %zu is not finite", i / 3);
    }
  /* the scene reads both arrays in place and keeps them */
  fr_scene *sc;
  fr_error e = fr_scene_from_buffers(pos, nv, 0, PyArray_DATA(t), nt, 0, FR_SHARE_BUFFERS, &sc);
  if (e != FR_OK) {
    Py_DECREF(v);
    Py_DECREF(t);
    return raise_fr(e, fr_last_error());
  }
  PyObject *result = wrap_scene(type, sc, smooth);
  if (!result) {
    Py_DECREF(v);
    Py_DECREF(t);
    return NULL;
  }
  ((SceneObject *)result)->shared_vertices = (PyObject *)v;
  ((SceneObject *)result)->shared_triangles = (PyObject *)t;
  return result;
}

static PyObject *scene_load(PyObject *cls, PyObject *args, PyObject *kw) {
  static char *names[] = {"path", "smooth", NULL};
  PyObject *path;
  float smooth = 30.0f;
  if (!PyArg_ParseTupleAndKeywords(args, kw, "O&|f", names, PyUnicode_FSConverter, &path, &smooth)) return NULL;
  fr_scene *sc;
  fr_error e;
  Py_BEGIN_ALLOW_THREADS
  e = fr_scene_load(PyBytes_AS_STRING(path), &sc);
  Py_END_ALLOW_THREADS
  Py_DECREF(path);
  if (e != FR_OK) return raise_fr(e, fr_last_error());
  return wrap_scene((PyTypeObject *)cls, sc, smooth);
}

static PyObject *scene_builtin(PyObject *cls, PyObject *args, PyObject *kw) {
  static char *names[] = {"name", "smooth", NULL};
  const char *name = "default";
  float smooth = 30.0f;
  if (!PyArg_ParseTupleAndKeywords(args, kw, "|sf", names, &name, &smooth)) return NULL;
  fr_scene *sc;
  fr_error e;
  if (!strcmp(name, "default")) e = fr_scene_builtin(&sc);
  else if (!strcmp(name, "materials")) e = fr_scene_builtin_materials(&sc);
  else return PyErr_Format(PyExc_ValueError, "builtin: no scene named '%s' (default, materials)", name);
  if (e != FR_OK) return raise_fr(e, fr_last_error());
  return wrap_scene((PyTypeObject *)cls, sc, smooth);
}

static void scene_dealloc(SceneObject *s) {
  scene_release(s);
  Py_TYPE(s)->tp_free((PyObject *)s);
}

static PyObject *scene_close(SceneObject *s, PyObject *unused) {
  (void)unused;
  if (s->busy) {
    PyErr_SetString(PyExc_RuntimeError, "close: the scene is being traced by another thread");
    return NULL;
  }
  scene_release(s);
  Py_RETURN_NONE;
}

/* ---- rays in ----------------------------------------------------------------- */

typedef struct rays_in {
  PyArrayObject *org, *dir, *tnear_a, *tfar_a; /* tnear_a, tfar_a: NULL for a scalar */
  float tnear, tfar;
  size_t n;
  int ndim;            /* of the leading shape */
  npy_intp shape[NPY_MAXDIMS];
} rays_in;

static void rays_free(rays_in *r) {
  Py_XDECREF(r->org); Py_XDECREF(r->dir); Py_XDECREF(r->tnear_a); Py_XDECREF(r->tfar_a);
}

/* A range bound: a number, or a float array of one value per ray. */
static int range_arg(PyObject *o, const char *name, size_t n, float *value, PyArrayObject **arr) {
  *arr = NULL;
  if (PyFloat_Check(o) || PyLong_Check(o) || PyArray_IsScalar(o, Number)) {
    double d = PyFloat_AsDouble(o);
    if (d == -1.0 && PyErr_Occurred()) return 0;
    if (isnan(d)) { PyErr_Format(PyExc_ValueError, "%s is NaN", name); return 0; }
    *value = (float)d;
    return 1;
  }
  PyArrayObject *a = (PyArrayObject *)PyArray_FROM_OTF(o, NPY_FLOAT32, NPY_ARRAY_IN_ARRAY | NPY_ARRAY_FORCECAST);
  if (!a) return 0;
  if ((size_t)PyArray_SIZE(a) != n) {
    PyErr_Format(PyExc_ValueError, "%s: expected a number or one value per ray (%zu), got %zd values", name, n,
                 (Py_ssize_t)PyArray_SIZE(a));
    Py_DECREF(a);
    return 0;
  }
  *arr = a;
  return 1;
}

/* The leading shape and count of r->org, (..., 3). */
static void rays_shape(rays_in *r) {
  r->ndim = PyArray_NDIM(r->org) - 1;
  for (int i = 0; i < r->ndim; i++) r->shape[i] = PyArray_DIM(r->org, i);
  r->n = (size_t)(PyArray_SIZE(r->org) / 3);
}

static int rays_parse(PyObject *o, PyObject *d, PyObject *tnear, PyObject *tfar, rays_in *r) {
  memset(r, 0, sizeof *r);
  r->tfar = INFINITY;
  if (!(r->org = vec3_array(o, "origins")) || !(r->dir = vec3_array(d, "directions"))) goto fail;
  if (!PyArray_SAMESHAPE(r->org, r->dir)) {
    PyErr_SetString(PyExc_ValueError, "origins and directions must have the same shape");
    goto fail;
  }
  rays_shape(r);
  if (tnear && !range_arg(tnear, "tnear", r->n, &r->tnear, &r->tnear_a)) goto fail;
  if (tfar && !range_arg(tfar, "tfar", r->n, &r->tfar, &r->tfar_a)) goto fail;
  return 1;
fail:
  rays_free(r);
  return 0;
}

/* Rays [i0, i0 + k) packed, or rays idx[i0 .. i0 + k) where idx is not NULL;
 * 0 and the least bad ray's index in *bad (which it only lowers) where an
 * origin or direction is not finite or a range is NaN. */
static int rays_pack(const rays_in *r, const uint32_t *idx, size_t i0, size_t k, fr_ray *out, size_t *bad) {
  const float *o = (const float *)PyArray_DATA(r->org), *d = (const float *)PyArray_DATA(r->dir);
  const float *tn = r->tnear_a ? (const float *)PyArray_DATA(r->tnear_a) : NULL;
  const float *tf = r->tfar_a ? (const float *)PyArray_DATA(r->tfar_a) : NULL;
  int ok = 1;
  for (size_t j = 0; j < k; j++) {
    size_t i = idx ? idx[i0 + j] : i0 + j;
    if (idx && j + GATHER_AHEAD < k) {
      size_t f = idx[i0 + j + GATHER_AHEAD];
      __builtin_prefetch(o + 3 * f);
      __builtin_prefetch(d + 3 * f);
      if (tn) __builtin_prefetch(tn + f);
      if (tf) __builtin_prefetch(tf + f);
    }
    fr_ray *x = &out[j];
    for (int a = 0; a < 3; a++) { x->org[a] = o[3 * i + a]; x->dir[a] = d[3 * i + a]; }
    x->tnear = tn ? tn[i] : r->tnear;
    x->tfar = tf ? tf[i] : r->tfar;
    float s = x->org[0] + x->org[1] + x->org[2] + x->dir[0] + x->dir[1] + x->dir[2];
    if (!isfinite(s) || isnan(x->tnear) || isnan(x->tfar)) {
      int fine = 1;
      for (int a = 0; a < 3; a++) fine &= isfinite(x->org[a]) && isfinite(x->dir[a]);
      if (!fine || isnan(x->tnear) || isnan(x->tfar)) {
        ok = 0;
        if (i < *bad) *bad = i;
      }
    }
  }
  return ok;
}

static PyObject *bad_ray(size_t i) {
  return PyErr_Format(PyExc_ValueError, "ray %zu: an origin or direction is NaN or infinite, or a range is NaN", i);
}

static PyArrayObject *out_array(const rays_in *r, int extra, int type) {
  npy_intp shape[NPY_MAXDIMS];
  int nd = r->ndim;
  memcpy(shape, r->shape, sizeof(npy_intp) * (size_t)nd);
  if (extra) shape[nd++] = extra;
  return (PyArrayObject *)PyArray_SimpleNew(nd, shape, type);
}

/* Parses (origins, directions, tnear=0, tfar=inf) and marks the scene busy;
 * max_hits, when not NULL, comes third (intersect_all); normals (intersect)
 * and reorder (intersect, occluded) last. */
static int begin_trace(SceneObject *s, PyObject *args, PyObject *kw, rays_in *r, Py_ssize_t *max_hits, int *normals,
                       int *reorder) {
  static char *names[] = {"origins", "directions", "tnear", "tfar", "reorder", NULL};
  static char *names_all[] = {"origins", "directions", "max_hits", "tnear", "tfar", NULL};
  static char *names_normals[] = {"origins", "directions", "tnear", "tfar", "normals", "reorder", NULL};
  PyObject *o, *d, *tn = NULL, *tf = NULL;
  if (max_hits) {
    if (!PyArg_ParseTupleAndKeywords(args, kw, "OO|nOO", names_all, &o, &d, max_hits, &tn, &tf)) return 0;
    if (*max_hits < 0) { PyErr_SetString(PyExc_ValueError, "max_hits must be at least 0"); return 0; }
  } else if (normals) {
    if (!PyArg_ParseTupleAndKeywords(args, kw, "OO|OOpp", names_normals, &o, &d, &tn, &tf, normals, reorder))
      return 0;
  } else if (!PyArg_ParseTupleAndKeywords(args, kw, "OO|OOp", names, &o, &d, &tn, &tf, reorder))
    return 0;
  if (!scene_open(s) || !rays_parse(o, d, tn, tf, r)) return 0;
  s->busy++;
  return 1;
}

/* ---- the order of incoherent rays ---------------------------------------------
 * Rays with random origins share no nodes with their neighbours in the
 * array, so each fetches its own path through the tree from memory. With
 * reorder=True they are traced in the order of the cell of the scene's box
 * their origin lies in (16 per axis, along a Morton curve), so that rays
 * traced one after another walk the same nodes while they are in cache:
 * on large scenes that saves more than the order costs (docs/python.md).
 * Arrays whose neighbours mostly share a cell already (camera rays, points
 * in tiles) are traced as given. In single mode a ray's answer does not
 * depend on its neighbours; in the others, whose packets do, the answers
 * are those of another trace mode: t and the triangle the same, u and v to
 * rounding.
 *
 * The order is a stable counting sort of 4096 keys, the same on any number
 * of threads. The rays are fetched in it as they are packed (prefetched
 * ahead), and the answers, stored in the traced order, are read back in
 * the arrays' order, so that the outputs are written in runs. */
#define ORDER_MIN (1u << 15)   /* fewer rays are traced as given */
#define ORDER_ROUND (1u << 20) /* rays ordered at once, with 11-42 bytes of buffers each */
#define ORDER_KEYS 4096u       /* 16 cells per axis */

/* Where the answers go: hits (intersect) or occ (occluded). */
typedef struct answers {
  float *t, *u, *v, *ng; /* ng NULL without normals */
  uint32_t *prim;
  uint8_t *occ;
} answers;

/* Hit x of ray i into the arrays. */
static void answer_hit(const answers *out, size_t i, const fr_hit *x) {
  out->t[i] = x->t; out->u[i] = x->u; out->v[i] = x->v; out->prim[i] = x->prim;
  if (out->ng) for (int a = 0; a < 3; a++) out->ng[3 * i + a] = x->ng[a];
}

typedef struct ordered {
  uint32_t *ray;   /* ray[p]: the index in the arrays of the round's p-th ray to trace */
  uint32_t *at;    /* at[i]: where the round's ray i is in that order */
  uint16_t *key;
  uint32_t *count; /* per thread, ORDER_KEYS each */
  fr_hit *hit;     /* the answers in the traced order: hits or occ */
  uint8_t *occ;
} ordered;

static void ordered_free(ordered *o) {
  free(o->ray); free(o->at); free(o->key); free(o->count); free(o->hit); free(o->occ);
}

/* Buffers for rounds of n rays and these answers; 0 (and none) where n is
 * too small to order, or memory is short: the answers are the same. */
static int ordered_alloc(ordered *o, size_t n, int threads, const answers *out) {
  memset(o, 0, sizeof *o);
  if (n < ORDER_MIN || n > UINT32_MAX) return 0;
  size_t m = n < ORDER_ROUND ? n : ORDER_ROUND;
  o->ray = malloc(m * sizeof *o->ray);
  o->at = malloc(m * sizeof *o->at);
  o->key = malloc(m * sizeof *o->key);
  o->count = malloc((size_t)threads * ORDER_KEYS * sizeof *o->count);
  int ok = o->ray && o->at && o->key && o->count;
  if (out->occ) ok = ok && (o->occ = malloc(m));
  else ok = ok && (o->hit = malloc(m * sizeof *o->hit));
  if (!ok) ordered_free(o);
  return ok;
}

/* A cell coordinate (the scaled origin; NaN and the outside of the box go
 * to the border cells) with its 4 bits spread three apart. */
static uint32_t cell_bits(float c) {
  c = c > 0.0f ? c : 0.0f;
  uint32_t q = (uint32_t)(int32_t)(c < 15.0f ? c : 15.0f);
  return (q & 1u) | (q & 2u) << 2 | (q & 4u) << 4 | (q & 8u) << 6;
}

/* The order of rays [base, base + m) of r by their origins' cells into o,
 * on `threads` threads; 1 if so, 0 if they are coherent as given. */
static int rays_order(const rays_in *r, const fr_scene *sc, int threads, size_t base, size_t m, ordered *o) {
  float lo[3], hi[3], s[3];
  fr_scene_bounds(sc, lo, hi);
  for (int a = 0; a < 3; a++) s[a] = hi[a] > lo[a] ? 16.0f / (hi[a] - lo[a]) : 0.0f;
  const float *org = (const float *)PyArray_DATA(r->org) + 3 * base;
  size_t same = 0;
  int sorted = 0;
#pragma omp parallel num_threads(threads)
  {
    int t = omp_get_thread_num(), nt = omp_get_num_threads();
    size_t a = m * (size_t)t / (size_t)nt, b = m * (size_t)(t + 1) / (size_t)nt, mine = 0;
    uint32_t *c = o->count + (size_t)t * ORDER_KEYS;
    uint16_t *key = o->key;
    for (size_t i = a; i < b; i++)
      key[i] = (uint16_t)(cell_bits((org[3 * i] - lo[0]) * s[0]) | cell_bits((org[3 * i + 1] - lo[1]) * s[1]) << 1 |
                          cell_bits((org[3 * i + 2] - lo[2]) * s[2]) << 2);
    memset(c, 0, ORDER_KEYS * sizeof *c);
    for (size_t i = a; i < b; i++) c[key[i]]++;
    for (size_t i = a + 1; i < b; i++) mine += key[i] == key[i - 1];
#pragma omp atomic
    same += mine;
#pragma omp barrier
#pragma omp single
    {
      sorted = 2 * same < m; /* most neighbours in other cells: incoherent */
      uint32_t at = 0;
      for (uint32_t k = 0; sorted && k < ORDER_KEYS; k++)
        for (int u = 0; u < nt; u++) {
          uint32_t cnt = o->count[(size_t)u * ORDER_KEYS + k];
          o->count[(size_t)u * ORDER_KEYS + k] = at;
          at += cnt;
        }
    }
    if (sorted)
      for (size_t i = a; i < b; i++) {
        uint32_t p = c[key[i]]++;
        o->ray[p] = (uint32_t)(base + i);
        o->at[i] = p;
      }
  }
  return sorted;
}

/* ---- tracing arrays ---------------------------------------------------------------- */

/* Rays [base, base + m) of r in chunks as given, or, where o is not NULL,
 * in o's order with the answers put back in the arrays' order. *bad as
 * rays_pack. */
static void trace_round(const fr_scene *sc, const rays_in *r, int threads, size_t base, size_t m, const ordered *o,
                        const answers *out, size_t *bad) {
  size_t chunks = (m + CHUNK - 1) / CHUNK;
  int failed = 0;
#pragma omp parallel num_threads(threads)
  {
#pragma omp for schedule(dynamic, 1)
    for (size_t c = 0; c < chunks; c++) {
      fr_ray rays[CHUNK];
      fr_hit hits[CHUNK];
      size_t c0 = c * CHUNK, k = m - c0 < CHUNK ? m - c0 : CHUNK, b = (size_t)-1;
      if (!(o ? rays_pack(r, o->ray, c0, k, rays, &b) : rays_pack(r, NULL, base + c0, k, rays, &b))) {
#pragma omp critical(frusta_bad_ray)
        {
          if (b < *bad) *bad = b;
          failed = 1;
        }
        continue;
      }
      if (out->occ) {
        fr_occluded_stream(sc, rays, o ? o->occ + c0 : out->occ + base + c0, k);
        continue;
      }
      if (o) {
        fr_intersect_stream(sc, rays, o->hit + c0, k);
        continue;
      }
      fr_intersect_stream(sc, rays, hits, k);
      for (size_t j = 0; j < k; j++) answer_hit(out, base + c0 + j, &hits[j]);
    }
    /* the loop's closing barrier has made `failed` final */
    if (o && !failed) {
#pragma omp for schedule(static)
      for (size_t i = 0; i < m; i++) {
        size_t p = o->at[i], q = base + i;
        if (i + GATHER_AHEAD < m) {
          size_t f = o->at[i + GATHER_AHEAD];
          __builtin_prefetch(out->occ ? (const void *)&o->occ[f] : (const void *)&o->hit[f]);
        }
        if (out->occ) out->occ[q] = o->occ[p];
        else answer_hit(out, q, &o->hit[p]);
      }
    }
  }
}

/* All of r's rays on `threads` threads, in the order of their origins'
 * cells where `reorder` asks for it and they are enough and incoherent;
 * *bad as rays_pack. */
static void trace_arrays(const fr_scene *sc, const rays_in *r, int threads, int reorder, const answers *out,
                         size_t *bad) {
  size_t n = r->n;
  ordered o;
  int ordering = reorder && ordered_alloc(&o, n, threads, out);
  for (size_t base = 0; base < n && *bad == (size_t)-1;) {
    size_t m = ordering ? (n - base < ORDER_ROUND ? n - base : ORDER_ROUND) : n - base;
    if (ordering && !rays_order(r, sc, threads, base, m, &o)) { /* nor the rounds after */
      ordered_free(&o);
      ordering = 0;
    }
    trace_round(sc, r, threads, base, m, ordering ? &o : NULL, out, bad);
    base += m;
  }
  if (ordering) ordered_free(&o);
}

/* ---- intersect and occluded ------------------------------------------------------ */

/* normals=False: no normal array (None in its place), one output fewer to
 * allocate and fill */
static PyObject *scene_intersect(SceneObject *s, PyObject *args, PyObject *kw) {
  rays_in r;
  int normals = 1, reorder = 0;
  if (!begin_trace(s, args, kw, &r, NULL, &normals, &reorder)) return NULL;
  PyArrayObject *t = out_array(&r, 0, NPY_FLOAT32), *prim = out_array(&r, 0, NPY_UINT32);
  PyArrayObject *u = out_array(&r, 0, NPY_FLOAT32), *v = out_array(&r, 0, NPY_FLOAT32);
  PyArrayObject *ng = normals ? out_array(&r, 3, NPY_FLOAT32) : NULL;
  PyObject *result = NULL;
  if (!t || !prim || !u || !v || (normals && !ng)) goto done;
  size_t bad = (size_t)-1;
  answers out = {PyArray_DATA(t), PyArray_DATA(u), PyArray_DATA(v), ng ? PyArray_DATA(ng) : NULL, PyArray_DATA(prim),
                 NULL};
  const fr_scene *sc = s->scene;
  Py_BEGIN_ALLOW_THREADS
  trace_arrays(sc, &r, n_threads ? n_threads : omp_get_max_threads(), reorder, &out, &bad);
  Py_END_ALLOW_THREADS
  if (bad != (size_t)-1) { bad_ray(bad); goto done; }
  result = Py_BuildValue("(OOOOO)", t, prim, u, v, ng ? (PyObject *)ng : Py_None);
done:
  s->busy--;
  Py_XDECREF(t); Py_XDECREF(prim); Py_XDECREF(u); Py_XDECREF(v); Py_XDECREF(ng);
  rays_free(&r);
  return result;
}

static PyObject *scene_occluded(SceneObject *s, PyObject *args, PyObject *kw) {
  rays_in r;
  int reorder = 0;
  if (!begin_trace(s, args, kw, &r, NULL, NULL, &reorder)) return NULL;
  PyArrayObject *occ = out_array(&r, 0, NPY_BOOL);
  PyObject *result = NULL;
  if (!occ) goto done;
  size_t bad = (size_t)-1;
  /* numpy bools are bytes of 0 or 1, as the call writes */
  answers out = {NULL, NULL, NULL, NULL, NULL, PyArray_DATA(occ)};
  const fr_scene *sc = s->scene;
  Py_BEGIN_ALLOW_THREADS
  trace_arrays(sc, &r, n_threads ? n_threads : omp_get_max_threads(), reorder, &out, &bad);
  Py_END_ALLOW_THREADS
  if (bad != (size_t)-1) { bad_ray(bad); goto done; }
  result = (PyObject *)occ;
  Py_INCREF(result);
done:
  s->busy--;
  Py_XDECREF(occ);
  rays_free(&r);
  return result;
}

/* ---- all hits ------------------------------------------------------------------- */

/* One chunk's hits, packed: kept[j] of its rays' max_hits slots. */
typedef struct chunk_hits {
  fr_hit *hits;
  size_t kept;
} chunk_hits;

static PyObject *scene_intersect_all(SceneObject *s, PyObject *args, PyObject *kw) {
  rays_in r;
  Py_ssize_t max_hits = 16;
  if (!begin_trace(s, args, kw, &r, &max_hits, NULL, NULL)) return NULL;
  /* a chunk's slots take at most 64 * CHUNK hits, however large max_hits */
  size_t K = (size_t)max_hits, n = r.n, per = K <= 64 ? CHUNK : (K >= 64 * CHUNK ? 1 : 64 * CHUNK / K);
  size_t chunks = (n + per - 1) / per;
  PyArrayObject *count = out_array(&r, 0, NPY_UINT32);
  chunk_hits *ch = calloc(chunks ? chunks : 1, sizeof *ch);
  PyArrayObject *ray = NULL, *prim = NULL, *t = NULL, *u = NULL, *v = NULL;
  PyObject *result = NULL;
  if (!count || !ch) { if (!ch) PyErr_NoMemory(); goto done; }
  if (K > ((size_t)1 << 24)) { PyErr_SetString(PyExc_ValueError, "max_hits: at most 16777216"); goto done; }
  size_t bad = (size_t)-1;
  fr_error err = FR_OK;
  char msg[512] = "";
  const fr_scene *sc = s->scene;
  uint32_t *cp = PyArray_DATA(count);
  Py_BEGIN_ALLOW_THREADS
#pragma omp parallel for schedule(dynamic, 1) num_threads(n_threads ? n_threads : omp_get_max_threads())
  for (size_t c = 0; c < chunks; c++) {
    fr_ray rays[CHUNK];
    size_t i0 = c * per, k = n - i0 < per ? n - i0 : per, b = (size_t)-1;
    if (!rays_pack(&r, NULL, i0, k, rays, &b)) {
#pragma omp critical(frusta_bad_ray)
      if (b < bad) bad = b;
      continue;
    }
    fr_hit *h = K ? malloc(k * K * sizeof *h) : NULL;
    fr_error e = K && !h ? FR_ERR_NOMEM : fr_intersect_all(sc, rays, k, h, K, cp + i0);
    if (e != FR_OK) {
#pragma omp critical(frusta_error)
      if (err == FR_OK) { err = e; snprintf(msg, sizeof msg, "%s", e == FR_ERR_NOMEM && !h ? "out of memory" : fr_last_error()); }
      free(h);
      continue;
    }
    /* pack ray j's first min(count, K) slots together */
    size_t kept = 0;
    for (size_t j = 0; j < k; j++) {
      size_t m = cp[i0 + j] < K ? cp[i0 + j] : K;
      memmove(h + kept, h + j * K, m * sizeof *h);
      kept += m;
    }
    ch[c].hits = h;
    ch[c].kept = kept;
  }
  Py_END_ALLOW_THREADS
  if (bad != (size_t)-1) { bad_ray(bad); goto done; }
  if (err != FR_OK) { raise_fr(err, msg); goto done; }
  size_t total = 0;
  for (size_t c = 0; c < chunks; c++) total += ch[c].kept;
  npy_intp dim = (npy_intp)total;
  ray = (PyArrayObject *)PyArray_SimpleNew(1, &dim, NPY_INT64);
  prim = (PyArrayObject *)PyArray_SimpleNew(1, &dim, NPY_UINT32);
  t = (PyArrayObject *)PyArray_SimpleNew(1, &dim, NPY_FLOAT32);
  u = (PyArrayObject *)PyArray_SimpleNew(1, &dim, NPY_FLOAT32);
  v = (PyArrayObject *)PyArray_SimpleNew(1, &dim, NPY_FLOAT32);
  if (!ray || !prim || !t || !u || !v) goto done;
  int64_t *rp = PyArray_DATA(ray);
  uint32_t *pp = PyArray_DATA(prim);
  float *tp = PyArray_DATA(t), *up = PyArray_DATA(u), *vp = PyArray_DATA(v);
  size_t at = 0;
  for (size_t c = 0; c < chunks; c++) {
    size_t i0 = c * per, k = n - i0 < per ? n - i0 : per, q = 0;
    for (size_t j = 0; j < k; j++) {
      size_t m = cp[i0 + j] < K ? cp[i0 + j] : K;
      for (size_t h = 0; h < m; h++, q++, at++) {
        const fr_hit *x = &ch[c].hits[q];
        rp[at] = (int64_t)(i0 + j); pp[at] = x->prim; tp[at] = x->t; up[at] = x->u; vp[at] = x->v;
      }
    }
  }
  result = Py_BuildValue("(OOOOOO)", ray, prim, t, u, v, count);
done:
  s->busy--;
  if (ch)
    for (size_t c = 0; c < chunks; c++) free(ch[c].hits);
  free(ch);
  Py_XDECREF(count); Py_XDECREF(ray); Py_XDECREF(prim); Py_XDECREF(t); Py_XDECREF(u); Py_XDECREF(v);
  rays_free(&r);
  return result;
}

/* ---- camera rays by multi-frusta -------------------------------------------------- */

static int vec3_arg(PyObject *o, const char *name, float out[3]) {
  PyArrayObject *a = (PyArrayObject *)PyArray_FROM_OTF(o, NPY_FLOAT32, NPY_ARRAY_IN_ARRAY | NPY_ARRAY_FORCECAST);
  if (!a) return 0;
  int ok = PyArray_SIZE(a) == 3;
  if (ok) memcpy(out, PyArray_DATA(a), 3 * sizeof(float));
  for (int i = 0; ok && i < 3; i++) ok = isfinite(out[i]);
  Py_DECREF(a);
  if (!ok) PyErr_Format(PyExc_ValueError, "%s: expected 3 finite numbers", name);
  return ok;
}

static PyObject *scene_intersect_camera(SceneObject *s, PyObject *args, PyObject *kw) {
  static char *names[] = {"eye", "at", "up", "fov", "width", "height", "directions", "normals", NULL};
  PyObject *eo, *ao, *uo;
  fr_pinhole cam;
  int want_dir = 0, want_normals = 1;
  if (!PyArg_ParseTupleAndKeywords(args, kw, "OOOfii|pp", names, &eo, &ao, &uo, &cam.fov_deg, &cam.width,
                                   &cam.height, &want_dir, &want_normals))
    return NULL;
  if (!scene_open(s) || !vec3_arg(eo, "eye", cam.eye) || !vec3_arg(ao, "at", cam.at) || !vec3_arg(uo, "up", cam.up))
    return NULL;
  if (cam.width <= 0 || cam.height <= 0 || (int64_t)cam.width * cam.height > ((int64_t)1 << 28))
    return PyErr_Format(PyExc_ValueError, "intersect_camera: image size %dx%d is empty or too large", cam.width,
                        cam.height);
  rays_in r;
  memset(&r, 0, sizeof r);
  r.ndim = 2;
  r.shape[0] = cam.height;
  r.shape[1] = cam.width;
  PyArrayObject *t = out_array(&r, 0, NPY_FLOAT32), *prim = out_array(&r, 0, NPY_UINT32);
  PyArrayObject *u = out_array(&r, 0, NPY_FLOAT32), *v = out_array(&r, 0, NPY_FLOAT32);
  PyArrayObject *ng = want_normals ? out_array(&r, 3, NPY_FLOAT32) : NULL;
  PyArrayObject *dir = want_dir ? out_array(&r, 3, NPY_FLOAT32) : NULL;
  PyObject *result = NULL;
  if (!t || !prim || !u || !v || (want_normals && !ng) || (want_dir && !dir)) goto done;
  s->busy++;
  const fr_scene *sc = s->scene;
  int bands = (cam.height + 15) / 16;
  fr_error err = FR_OK;
  char msg[512] = "";
  float *tp = PyArray_DATA(t), *up = PyArray_DATA(u), *vp = PyArray_DATA(v), *np = ng ? PyArray_DATA(ng) : NULL;
  float *dp = dir ? PyArray_DATA(dir) : NULL;
  uint32_t *pp = PyArray_DATA(prim);
  Py_BEGIN_ALLOW_THREADS
#pragma omp parallel for schedule(dynamic, 1) num_threads(n_threads ? n_threads : omp_get_max_threads())
  for (int band = 0; band < bands; band++) {
    int y0 = 16 * band, rows = cam.height - y0 < 16 ? cam.height - y0 : 16;
    const size_t i0 = (size_t)y0 * (size_t)cam.width;
    const fr_hit_arrays out = {tp + i0, up + i0, vp + i0, pp + i0, np ? np + 3 * i0 : NULL, dp ? dp + 3 * i0 : NULL};
    fr_error e = fr_intersect_camera_arrays(sc, &cam, y0, rows, &out);
    if (e != FR_OK) {
#pragma omp critical(frusta_error)
      if (err == FR_OK) { err = e; snprintf(msg, sizeof msg, "%s", fr_last_error()); }
    }
  }
  Py_END_ALLOW_THREADS
  s->busy--;
  if (err != FR_OK) { raise_fr(err, msg); goto done; }
  result = Py_BuildValue("(OOOOOO)", t, prim, u, v, ng ? (PyObject *)ng : Py_None, dir ? (PyObject *)dir : Py_None);
done:
  Py_XDECREF(t); Py_XDECREF(prim); Py_XDECREF(u); Py_XDECREF(v); Py_XDECREF(ng); Py_XDECREF(dir);
  return result;
}

/* Points of shape (..., 3) in r->org (r->dir unused); whether they are
 * finite is for first_bad_point, on the threads. */
static int points_parse(PyObject *po, rays_in *r) {
  memset(r, 0, sizeof *r);
  if (!(r->org = vec3_array(po, "points"))) return 0;
  rays_shape(r);
  return 1;
}

/* The first of n points (3 floats each) with a coordinate NaN or infinite,
 * or SIZE_MAX: a pass over the bits that compilers vectorize, and a search
 * only where it found one. */
static size_t first_bad_point(const float *p, size_t n) {
  uint32_t any = 0;
  for (size_t i = 0; i < 3 * n; i++) {
    uint32_t b;
    memcpy(&b, p + i, sizeof b);
    any |= (uint32_t)((b & 0x7f800000u) == 0x7f800000u);
  }
  if (!any) return SIZE_MAX;
  for (size_t i = 0; i < 3 * n; i++)
    if (!isfinite(p[i])) return i / 3;
  return SIZE_MAX;
}

/* Keeps the smallest point index a thread found bad. */
static void note_bad_point(size_t *bad, size_t found) {
  if (found == SIZE_MAX) return;
#pragma omp critical(frusta_bad_point)
  if (found < *bad) *bad = found;
}

static PyObject *bad_point(size_t i) { return PyErr_Format(PyExc_ValueError, "point %zu is NaN or infinite", i); }

/* The distance left out at a point's end of a shadow ray. */
static int eps_arg(float eps) {
  if (eps >= 0.0f && isfinite(eps)) return 1;
  PyErr_SetString(PyExc_ValueError, "eps: expected a finite number >= 0");
  return 0;
}

static PyObject *scene_occluded_point_light(SceneObject *s, PyObject *args, PyObject *kw) {
  static char *names[] = {"points", "light", "eps", NULL};
  PyObject *po, *lo;
  float light[3], eps;
  if (!PyArg_ParseTupleAndKeywords(args, kw, "OOf", names, &po, &lo, &eps)) return NULL;
  if (!scene_open(s) || !vec3_arg(lo, "light", light)) return NULL;
  if (!eps_arg(eps)) return NULL;
  rays_in r;
  if (!points_parse(po, &r)) return NULL;
  const float *pts = PyArray_DATA(r.org);
  PyArrayObject *occ = out_array(&r, 0, NPY_BOOL);
  if (!occ) { rays_free(&r); return NULL; }
  s->busy++;
  const fr_scene *sc = s->scene;
  uint8_t *op = PyArray_DATA(occ);
  size_t n = r.n, per = 4 * CHUNK, chunks = (n + per - 1) / per, bad = SIZE_MAX;
  Py_BEGIN_ALLOW_THREADS
#pragma omp parallel for schedule(dynamic, 1) num_threads(n_threads ? n_threads : omp_get_max_threads())
  for (size_t c = 0; c < chunks; c++) {
    size_t i0 = c * per, k = n - i0 < per ? n - i0 : per, b = first_bad_point(pts + 3 * i0, k);
    if (b != SIZE_MAX) { note_bad_point(&bad, i0 + b); continue; }
    fr_occluded_point_light(sc, light, pts + 3 * i0, k, eps, op + i0); /* arguments checked above */
  }
  Py_END_ALLOW_THREADS
  s->busy--;
  rays_free(&r);
  if (bad != SIZE_MAX) {
    Py_DECREF(occ);
    return bad_point(bad);
  }
  return (PyObject *)occ;
}

static PyObject *scene_visibility_area_light(SceneObject *s, PyObject *args, PyObject *kw) {
  static char *names[] = {"points", "corner", "e1", "e2", "samples", "seed", "eps", NULL};
  PyObject *po, *co, *e1o, *e2o;
  float c[3], e1[3], e2[3], eps;
  int samples;
  unsigned long long seed;
  if (!PyArg_ParseTupleAndKeywords(args, kw, "OOOOiKf", names, &po, &co, &e1o, &e2o, &samples, &seed, &eps))
    return NULL;
  if (!scene_open(s) || !vec3_arg(co, "corner", c) || !vec3_arg(e1o, "e1", e1) || !vec3_arg(e2o, "e2", e2)) return NULL;
  if (samples < 16 || samples > 4096 || samples % 16)
    return PyErr_Format(PyExc_ValueError, "samples: %d is not a multiple of 16 in 16..4096", samples);
  if (!eps_arg(eps)) return NULL;
  rays_in r;
  if (!points_parse(po, &r)) return NULL;
  const float *pts = PyArray_DATA(r.org);
  PyArrayObject *vis = out_array(&r, 0, NPY_FLOAT32);
  if (!vis) { rays_free(&r); return NULL; }
  s->busy++;
  const fr_scene *sc = s->scene;
  float *vp = PyArray_DATA(vis);
  size_t n = r.n, per = 16 * 256, chunks = (n + per - 1) / per; /* whole batches of 256 points */
  int failed = 0;
  size_t bad = SIZE_MAX;
  Py_BEGIN_ALLOW_THREADS
#pragma omp parallel for schedule(dynamic, 1) num_threads(n_threads ? n_threads : omp_get_max_threads())
  for (size_t ch = 0; ch < chunks; ch++) {
    size_t i0 = ch * per, k = n - i0 < per ? n - i0 : per, b = first_bad_point(pts + 3 * i0, k);
    if (b != SIZE_MAX) { note_bad_point(&bad, i0 + b); continue; }
    if (fr_visibility_area_light(sc, c, e1, e2, pts + 3 * i0, k, samples, seed, eps, vp + i0) != FR_OK) {
#pragma omp atomic write
      failed = 1;
    }
  }
  Py_END_ALLOW_THREADS
  s->busy--;
  rays_free(&r);
  if (bad != SIZE_MAX) {
    Py_DECREF(vis);
    return bad_point(bad);
  }
  if (failed) { /* arguments were checked: only memory can fail */
    Py_DECREF(vis);
    return PyErr_NoMemory();
  }
  return (PyObject *)vis;
}

/* ---- rendering --------------------------------------------------------------------- */

static const char *shade_names[] = {"eyelight", "normals", "shadows", "softshadow", "whitted", "ao", "path"};

/* A float keyword argument when given (not None). */
static int float_arg(PyObject *o, const char *name, float *out) {
  if (o == Py_None) return 1;
  const double v = PyFloat_AsDouble(o);
  if (v == -1.0 && PyErr_Occurred()) {
    PyErr_Clear();
    PyErr_Format(PyExc_TypeError, "render: %s wants a number", name);
    return 0;
  }
  *out = (float)v;
  return 1;
}

/* An int keyword argument when given (not None). */
static int int_arg(PyObject *o, const char *name, long lo, long hi, long *out) {
  if (o == Py_None) return 1;
  const long v = PyLong_AsLong(o);
  if (v == -1 && PyErr_Occurred()) {
    PyErr_Clear();
    PyErr_Format(PyExc_TypeError, "render: %s wants an integer", name);
    return 0;
  }
  if (v < lo || v > hi) {
    PyErr_Format(PyExc_ValueError, "render: %s %ld is not in %ld..%ld", name, v, lo, hi);
    return 0;
  }
  *out = v;
  return 1;
}

static PyObject *scene_render(SceneObject *s, PyObject *args, PyObject *kw) {
  static char *names[] = {"width", "height", "shade", "eye", "at", "up", "fov", "spp", "light", "environment",
                          "exposure", "denoise", "display", "max_depth", "sampler", "seed", "aperture", "focus",
                          "env_color", "env_intensity", "env_rotate", NULL};
  PyObject *wo = Py_None, *ho = Py_None, *so = Py_None, *eo = Py_None, *ao = Py_None, *uo = Py_None, *fo = Py_None;
  PyObject *sppo = Py_None, *lo = Py_None, *envo = Py_None, *expo = Py_None, *mdo = Py_None, *samo = Py_None;
  PyObject *seedo = Py_None, *apo = Py_None, *foco = Py_None, *co = Py_None, *eio = Py_None, *ero = Py_None;
  int denoise = 0, display = 1;
  if (!PyArg_ParseTupleAndKeywords(args, kw, "|OOOOOOOOOOOppOOOOOOOO", names, &wo, &ho, &so, &eo, &ao, &uo, &fo, &sppo,
                                   &lo, &envo, &expo, &denoise, &display, &mdo, &samo, &seedo, &apo, &foco, &co, &eio,
                                   &ero))
    return NULL;
  if (!scene_open(s)) return NULL;
  fr_render_desc d; /* the scene file's settings, then the arguments given */
  fr_error e = fr_render_desc_of_scene(s->scene, &d);
  if (e) return raise_fr(e, fr_last_error());
  long width = d.camera.width, height = d.camera.height, spp = d.spp, max_depth = d.max_depth, seed = d.seed;
  if (!int_arg(wo, "width", 1, 1 << 16, &width) || !int_arg(ho, "height", 1, 1 << 16, &height) ||
      !int_arg(sppo, "spp", 1, 65536, &spp) || !int_arg(mdo, "max_depth", 0, 64, &max_depth) ||
      !int_arg(seedo, "seed", 0, 0xFFFFFFFFl, &seed) || !float_arg(expo, "exposure", &d.exposure) ||
      !float_arg(apo, "aperture", &d.aperture) || !float_arg(foco, "focus", &d.focus) ||
      !float_arg(eio, "env_intensity", &d.env_intensity) || !float_arg(ero, "env_rotate", &d.env_rotate))
    return NULL;
  if (width <= 0 || height <= 0 || (int64_t)width * height > ((int64_t)1 << 26))
    return PyErr_Format(PyExc_ValueError, "render: image size %ldx%ld is empty or too large (give width and height)",
                        width, height);
  const int W = (int)width, H = (int)height;
  d.camera.width = W, d.camera.height = H;
  d.spp = (int)spp, d.max_depth = (int)max_depth, d.seed = (uint32_t)seed;
  if (so != Py_None) {
    const char *shade = PyUnicode_Check(so) ? PyUnicode_AsUTF8(so) : NULL;
    int m = -1;
    for (int k = 0; shade && k < 7; k++)
      if (!strcmp(shade, shade_names[k])) m = k;
    if (m < 0)
      return PyErr_Format(PyExc_ValueError, "render: shade %R is none of eyelight, normals, shadows, softshadow, "
                          "whitted, ao, path", so);
    d.shade = (fr_render_shade)m;
  }
  if (samo != Py_None) {
    const char *sampler = PyUnicode_Check(samo) ? PyUnicode_AsUTF8(samo) : "";
    if (sampler && !strcmp(sampler, "hammersley")) d.sampler = FR_SAMPLER_HAMMERSLEY;
    else if (sampler && !strcmp(sampler, "sobol")) d.sampler = FR_SAMPLER_SOBOL;
    else return PyErr_Format(PyExc_ValueError, "render: sampler %R is neither hammersley nor sobol", samo);
  }
  if (co != Py_None && !vec3_arg(co, "env_color", d.env_color)) return NULL;
  if ((eo != Py_None) != (ao != Py_None))
    return PyErr_Format(PyExc_ValueError, "render: give eye and at together (or neither: the scene's own view)");
  if (eo != Py_None) {
    float upv[3] = {0.0f, 1.0f, 0.0f}, fov = 50.0f;
    if (!vec3_arg(eo, "eye", d.camera.eye) || !vec3_arg(ao, "at", d.camera.at) ||
        (uo != Py_None && !vec3_arg(uo, "up", upv)) || !float_arg(fo, "fov", &fov))
      return NULL;
    memcpy(d.camera.up, upv, sizeof upv);
    d.camera.fov_deg = fov;
  } else if (uo != Py_None || fo != Py_None) {
    return PyErr_Format(PyExc_ValueError, "render: up and fov need eye and at");
  }
  if (lo != Py_None) {
    if (!vec3_arg(lo, "light", d.light)) return NULL;
    d.has_light = 1;
  }
  PyObject *env = NULL;
  if (envo != Py_None) {
    if (!PyUnicode_FSConverter(envo, &env)) return NULL;
    d.environment = PyBytes_AS_STRING(env);
  }
  d.denoise = denoise, d.threads = n_threads;
  npy_intp dims[3] = {H, W, 3}, dims1[2] = {H, W};
  PyArrayObject *img = (PyArrayObject *)PyArray_SimpleNew(3, dims, NPY_FLOAT32);
  PyArrayObject *alb = (PyArrayObject *)PyArray_SimpleNew(3, dims, NPY_FLOAT32);
  PyArrayObject *nrm = (PyArrayObject *)PyArray_SimpleNew(3, dims, NPY_FLOAT32);
  PyArrayObject *dep = (PyArrayObject *)PyArray_SimpleNew(2, dims1, NPY_FLOAT32);
  PyObject *result = NULL;
  if (!img || !alb || !nrm || !dep) goto done;
  s->busy++;
  const fr_scene *sc = s->scene;
  char msg[512] = "";
  int got_spp = 0;
  Py_BEGIN_ALLOW_THREADS
  fr_renderer *r = NULL;
  e = fr_renderer_new(sc, &d, &r);
  if (!e) e = fr_renderer_render(r);
  if (!e) e = fr_renderer_image(r, display, PyArray_DATA(img), PyArray_DATA(alb), PyArray_DATA(nrm), PyArray_DATA(dep));
  if (e) snprintf(msg, sizeof msg, "%s", fr_last_error());
  got_spp = fr_renderer_spp(r);
  fr_renderer_release(r);
  Py_END_ALLOW_THREADS
  s->busy--;
  if (e) { raise_fr(e, msg); goto done; }
  result = Py_BuildValue("(OOOOi)", img, alb, nrm, dep, got_spp);
done:
  Py_XDECREF(env);
  Py_XDECREF(img); Py_XDECREF(alb); Py_XDECREF(nrm); Py_XDECREF(dep);
  return result;
}

/* ---- properties ------------------------------------------------------------------ */

static const char *mode_names[] = {"auto", "single", "packet8", "packet16", "hybrid16", "raystream"};
#define N_MODES 6

static PyObject *scene_get_mode(SceneObject *s, void *c) {
  (void)c;
  if (!scene_open(s)) return NULL;
  int m = (int)fr_scene_get_trace_mode(s->scene);
  return PyUnicode_FromString(m >= 0 && m < N_MODES ? mode_names[m] : "auto");
}

static int scene_set_mode(SceneObject *s, PyObject *value, void *c) {
  (void)c;
  if (!scene_open(s)) return -1;
  const char *name = value ? PyUnicode_AsUTF8(value) : NULL;
  if (!name) { if (!PyErr_Occurred()) PyErr_SetString(PyExc_TypeError, "trace_mode: expected a name"); return -1; }
  if (s->busy) { PyErr_SetString(PyExc_RuntimeError, "trace_mode: the scene is being traced"); return -1; }
  for (int m = 0; m < N_MODES; m++)
    if (!strcmp(name, mode_names[m])) return fr_scene_set_trace_mode(s->scene, (fr_trace_mode)m) == FR_OK ? 0 : -1;
  PyErr_Format(PyExc_ValueError, "trace_mode: '%s' is none of auto, single, packet8, packet16, hybrid16, raystream",
               name);
  return -1;
}

static PyObject *scene_triangle_count(SceneObject *s, void *c) {
  (void)c;
  return scene_open(s) ? PyLong_FromSize_t(fr_scene_triangle_count(s->scene)) : NULL;
}

static PyObject *scene_bounds(SceneObject *s, void *c) {
  (void)c;
  if (!scene_open(s)) return NULL;
  float lo[3], hi[3];
  fr_scene_bounds(s->scene, lo, hi);
  npy_intp dims[2] = {2, 3};
  PyArrayObject *b = (PyArrayObject *)PyArray_SimpleNew(2, dims, NPY_FLOAT32);
  if (!b) return NULL;
  float *p = PyArray_DATA(b);
  memcpy(p, lo, sizeof lo);
  memcpy(p + 3, hi, sizeof hi);
  return (PyObject *)b;
}

/* Copies of the scene's arrays (after loading: fan-triangulated, in file
 * order): an (n, 3) array of type from src's n rows of three 4-byte values. */
static PyObject *rows_copy(size_t n, int type, const void *src) {
  npy_intp dims[2] = {(npy_intp)n, 3};
  PyArrayObject *a = (PyArrayObject *)PyArray_SimpleNew(2, dims, type);
  if (a && n) memcpy(PyArray_DATA(a), src, n * 3 * 4);
  return (PyObject *)a;
}

static PyObject *scene_vertices(SceneObject *s, void *c) {
  (void)c;
  return scene_open(s) ? rows_copy(fr_scene_vertex_count(s->scene), NPY_FLOAT32, fr_scene_vertices(s->scene)) : NULL;
}

static PyObject *scene_triangles(SceneObject *s, void *c) {
  (void)c;
  return scene_open(s) ? rows_copy(fr_scene_triangle_count(s->scene), NPY_UINT32, fr_scene_indices(s->scene)) : NULL;
}

static PyMethodDef scene_methods[] = {
    {"load", (PyCFunction)(void (*)(void))scene_load, METH_VARARGS | METH_KEYWORDS | METH_CLASS,
     "load(path, smooth=30): a scene file (PLY, OBJ, any Assimp format, .zst); smooth: the crease angle of the "
     "shading normals made where the file has none (0: flat), as frusta render"},
    {"builtin", (PyCFunction)(void (*)(void))scene_builtin, METH_VARARGS | METH_KEYWORDS | METH_CLASS,
     "builtin(name='default', smooth=30): a built-in scene (default, materials)"},
    {"close", (PyCFunction)scene_close, METH_NOARGS, "close(): frees the scene now"},
    {"_intersect", (PyCFunction)(void (*)(void))scene_intersect, METH_VARARGS | METH_KEYWORDS, NULL},
    {"_occluded", (PyCFunction)(void (*)(void))scene_occluded, METH_VARARGS | METH_KEYWORDS, NULL},
    {"_intersect_all", (PyCFunction)(void (*)(void))scene_intersect_all, METH_VARARGS | METH_KEYWORDS, NULL},
    {"_occluded_point_light", (PyCFunction)(void (*)(void))scene_occluded_point_light, METH_VARARGS | METH_KEYWORDS,
     NULL},
    {"_visibility_area_light", (PyCFunction)(void (*)(void))scene_visibility_area_light,
     METH_VARARGS | METH_KEYWORDS, NULL},
    {"_render", (PyCFunction)(void (*)(void))scene_render, METH_VARARGS | METH_KEYWORDS, NULL},
    {"_intersect_camera", (PyCFunction)(void (*)(void))scene_intersect_camera, METH_VARARGS | METH_KEYWORDS, NULL},
    {NULL, NULL, 0, NULL}};

static PyGetSetDef scene_getset[] = {
    {"trace_mode", (getter)scene_get_mode, (setter)scene_set_mode, "how streams are traced", NULL},
    {"triangle_count", (getter)scene_triangle_count, NULL, "triangles in the scene", NULL},
    {"bounds", (getter)scene_bounds, NULL, "[[xmin, ymin, zmin], [xmax, ymax, zmax]]", NULL},
    {"vertices", (getter)scene_vertices, NULL, "a copy of the vertex positions, (n, 3) float32", NULL},
    {"triangles", (getter)scene_triangles, NULL, "a copy of the triangles' vertex indices, (n, 3) uint32", NULL},
    {NULL, NULL, NULL, NULL, NULL}};

static PyTypeObject SceneType = {
    PyVarObject_HEAD_INIT(NULL, 0).tp_name = "frusta._frusta.Scene",
    .tp_basicsize = sizeof(SceneObject),
    .tp_flags = Py_TPFLAGS_DEFAULT | Py_TPFLAGS_BASETYPE,
    .tp_doc = "Scene(vertices, triangles): a committed triangle scene",
    .tp_new = scene_new,
    .tp_dealloc = (destructor)scene_dealloc,
    .tp_methods = scene_methods,
    .tp_getset = scene_getset,
};

/* ---- the module --------------------------------------------------------------- */

static PyObject *set_threads(PyObject *m, PyObject *args) {
  (void)m;
  int n;
  if (!PyArg_ParseTuple(args, "i", &n)) return NULL;
  if (n < 0 || n > 4096) return PyErr_Format(PyExc_ValueError, "set_threads: %d is not in 0..4096", n);
  n_threads = n;
  Py_RETURN_NONE;
}

static PyObject *get_threads(PyObject *m, PyObject *unused) {
  (void)m; (void)unused;
  return PyLong_FromLong(n_threads ? n_threads : omp_get_max_threads());
}

static PyObject *isa(PyObject *m, PyObject *unused) {
  (void)m; (void)unused;
  return PyUnicode_FromString(fr_isa_name(fr_get_isa()));
}

/* save_image(path, rgb): an (h, w, 3) float image through fr_image_save. */
static PyObject *save_image(PyObject *m, PyObject *args) {
  (void)m;
  PyObject *path, *img;
  if (!PyArg_ParseTuple(args, "O&O", PyUnicode_FSConverter, &path, &img)) return NULL;
  PyArrayObject *a = vec3_array(img, "rgb");
  if (!a) { Py_DECREF(path); return NULL; }
  if (PyArray_NDIM(a) != 3 || PyArray_DIM(a, 0) < 1 || PyArray_DIM(a, 1) < 1 || PyArray_DIM(a, 0) > INT_MAX ||
      PyArray_DIM(a, 1) > INT_MAX) {
    Py_DECREF(path);
    Py_DECREF(a);
    return PyErr_Format(PyExc_ValueError, "rgb: expected shape (height, width, 3)");
  }
  const int h = (int)PyArray_DIM(a, 0), w = (int)PyArray_DIM(a, 1);
  fr_error e;
  Py_BEGIN_ALLOW_THREADS
  e = fr_image_save(PyBytes_AS_STRING(path), w, h, PyArray_DATA(a));
  Py_END_ALLOW_THREADS
  Py_DECREF(path);
  Py_DECREF(a);
  if (e != FR_OK) return raise_fr(e, fr_last_error());
  Py_RETURN_NONE;
}

static PyMethodDef module_methods[] = {
    {"save_image", save_image, METH_VARARGS,
     "save_image(path, rgb): writes an (h, w, 3) float image by the extension: .png (8-bit sRGB of display "
     "values in [0, 1]), .exr, .pfm (linear)"},
    {"set_threads", set_threads, METH_VARARGS, "set_threads(n): threads per call (0: all cores)"},
    {"get_threads", get_threads, METH_NOARGS, "threads a call uses"},
    {"isa", isa, METH_NOARGS, "the instruction set the kernels use"},
    {NULL, NULL, 0, NULL}};

static struct PyModuleDef module_def = {PyModuleDef_HEAD_INIT, "_frusta", "frusta's C extension", -1, module_methods,
                                        NULL, NULL, NULL, NULL};

PyMODINIT_FUNC PyInit__frusta(void) {
  import_array();
  if (PyType_Ready(&SceneType) < 0) return NULL;
  PyObject *m = PyModule_Create(&module_def);
  if (!m) return NULL;
  Py_INCREF(&SceneType);
  if (PyModule_AddObject(m, "Scene", (PyObject *)&SceneType) < 0) {
    Py_DECREF(&SceneType);
    Py_DECREF(m);
    return NULL;
  }
  PyModule_AddIntConstant(m, "INVALID_ID", (long)FR_INVALID_ID);
  PyModule_AddIntConstant(m, "VERSION_MAJOR", FR_VERSION_MAJOR);
  PyModule_AddIntConstant(m, "VERSION_MINOR", FR_VERSION_MINOR);
  return m;
}
