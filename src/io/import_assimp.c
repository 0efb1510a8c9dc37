/*
 * Everything that is not PLY or OBJ goes through Assimp's C API (glTF, FBX,
 * 3DS, ...). Meshes are flattened with their node transforms; triangle
 * numbers follow the node tree, depth first, each node's meshes in order.
 *
 * Assimp runs in a child process: an untrusted file must not take the
 * process down, and some files crash Assimp, abort in its assertions, loop,
 * or make it allocate what their headers claim. The child reads the scene
 * through a file system confined to the scene's folder (io/assimp_files.h),
 * under limits on memory and time, and sends the mesh back through a pipe;
 * a child that dies is a one-line error. A .zst file is inflated and handed
 * to Assimp from memory under the name without .zst.
 */
#include <errno.h>
#include <fcntl.h>
#include <signal.h>
#include <stdio.h>
#include <assimp/cimport.h>
#include <assimp/material.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>
#include "base/error.h"
#include "io/assimp_files.h"
#include "io/file_read.h"
#include "io/import.h"
#include "io/scene_path.h"

/* The child's allowance: this much time, and memory beyond what the process
 * already maps of this many bytes plus a multiple of the file's size. */
#define ASSIMP_SECONDS 120
#define ASSIMP_MEMORY_BASE ((size_t)1 << 30)
#define ASSIMP_MEMORY_PER_BYTE 64u

#if defined(__SANITIZE_ADDRESS__)
#define FR_ASAN 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define FR_ASAN 1
#endif
#endif

/* key, type, index: the triple Assimp's AI_MATKEY_* macros expand to */
static void copy_color(const struct aiMaterial *am, const char *key, unsigned type, unsigned index, float out[3]) {
  struct aiColor4D c;
  if (aiGetMaterialColor(am, key, type, index, &c) == aiReturn_SUCCESS) { out[0] = c.r; out[1] = c.g; out[2] = c.b; }
}

/* One mesh, its vertices moved by the node transform t (NULL: none). */
static fr_error add_mesh(const struct aiMesh *am, const struct aiMatrix4x4 *t, uint32_t mat, fr_mesh *m) {
  if (m->nverts + am->mNumVertices >= 0xFFFFFFF0u) return fr_fail(FR_ERR_UNSUPPORTED, "too many vertices");
  if ((am->mNumVertices && !am->mVertices) || (am->mNumFaces && !am->mFaces)) return FR_OK; /* nothing to read */
  const uint32_t base = (uint32_t)m->nverts;
  fr_error e = FR_OK;
  for (unsigned v = 0; v < am->mNumVertices && !e; v++) {
    struct aiVector3D p = am->mVertices[v];
    if (t) aiTransformVecByMatrix4(&p, t);
    e = fr_mesh_add_vertex(m, p.x, p.y, p.z);
  }
  /* texture coordinates per vertex (the first set), aligned with the
   * vertices (0, 0 where a mesh has none) */
  for (unsigned v = 0; v < am->mNumVertices && !e; v++) {
    const struct aiVector3D st = am->mTextureCoords[0] ? am->mTextureCoords[0][v] : (struct aiVector3D){0, 0, 0};
    e = fr_mesh_add_uv(m, st.x, st.y);
  }
  /* normals per vertex, aligned with the vertices (0, 0, 0 where a mesh has
   * none), turned by the transform's linear part: exact for rotations and
   * uniform scales, which is what scene graphs hold */
  for (unsigned v = 0; v < am->mNumVertices && !e; v++) {
    struct aiVector3D n = {0, 0, 0};
    if (am->mNormals) {
      n = am->mNormals[v];
      if (t) {
        struct aiMatrix3x3 r;
        aiMatrix3FromMatrix4(&r, t);
        aiTransformVecByMatrix3(&n, &r);
      }
    }
    e = fr_mesh_add_normal(m, n.x, n.y, n.z);
  }
  for (unsigned f = 0; f < am->mNumFaces && !e; f++) {
    const struct aiFace *face = &am->mFaces[f];
    for (unsigned j = 2; j < face->mNumIndices && face->mIndices && !e; j++)
      e = fr_mesh_add_triangle(m, base + face->mIndices[0], base + face->mIndices[j - 1], base + face->mIndices[j], mat);
  }
  return e;
}

/* The meshes of node and its children, each moved by its nodes' transforms
 * (parent times child), as Assimp's PreTransformVertices step would, which
 * asserts on some files. */
#define MAX_NODE_DEPTH 256
static fr_error add_node(const struct aiScene *sc, const struct aiNode *node, const struct aiMatrix4x4 *parent,
                         const uint32_t *matmap, fr_mesh *m, int depth) {
  if (depth > MAX_NODE_DEPTH) return fr_fail(FR_ERR_FORMAT, "scene nodes nested deeper than %d", MAX_NODE_DEPTH);
  struct aiMatrix4x4 t = node->mTransformation;
  if (parent) {
    struct aiMatrix4x4 p = *parent;
    aiMultiplyMatrix4(&p, &node->mTransformation);
    t = p;
  }
  fr_error e = FR_OK;
  for (unsigned i = 0; i < node->mNumMeshes && node->mMeshes && !e; i++) {
    if (node->mMeshes[i] >= sc->mNumMeshes || !sc->mMeshes[node->mMeshes[i]]) return fr_fail(FR_ERR_FORMAT, "a node names mesh %u of %u", node->mMeshes[i], sc->mNumMeshes);
    const struct aiMesh *am = sc->mMeshes[node->mMeshes[i]];
    const uint32_t mat = am->mMaterialIndex < sc->mNumMaterials ? matmap[am->mMaterialIndex] : FR_INVALID_ID;
    e = add_mesh(am, &t, mat, m);
  }
  /* Assimp's importers are not all consistent: counts can exceed the
   * pointers behind them (its RAW reader leaves children NULL) */
  for (unsigned c = 0; c < node->mNumChildren && node->mChildren && !e; c++)
    if (node->mChildren[c]) e = add_node(sc, node->mChildren[c], &t, matmap, m, depth + 1);
  return e;
}

static fr_error convert(const struct aiScene *sc, const char *path, fr_mesh *m) {
  uint32_t *matmap = calloc(sc->mNumMaterials + 1, sizeof(uint32_t));
  if (!matmap) return fr_fail(FR_ERR_NOMEM, "out of memory");
  for (unsigned i = 0; i < sc->mNumMaterials; i++) {
    const struct aiMaterial *am = sc->mMaterials ? sc->mMaterials[i] : NULL;
    struct aiString name;
    char nm[64];
    if (am && aiGetMaterialString(am, AI_MATKEY_NAME, &name) == aiReturn_SUCCESS) snprintf(nm, sizeof nm, "%s", name.data);
    else snprintf(nm, sizeof nm, "material_%u", i);
    fr_error e = fr_mesh_material(m, nm, &matmap[i]);
    if (e) { free(matmap); return e; }
    if (!am) continue;
    fr_material *fm = &m->mats[matmap[i]];
    copy_color(am, AI_MATKEY_COLOR_DIFFUSE, fm->diffuse);
    copy_color(am, AI_MATKEY_COLOR_SPECULAR, fm->specular);
    copy_color(am, AI_MATKEY_COLOR_EMISSIVE, fm->emission);
    copy_color(am, AI_MATKEY_COLOR_TRANSPARENT, fm->transmission);
    float f;
    unsigned one = 1;
    if (aiGetMaterialFloatArray(am, AI_MATKEY_SHININESS, &f, &one) == aiReturn_SUCCESS) fm->shininess = f;
    one = 1;
    if (aiGetMaterialFloatArray(am, AI_MATKEY_REFRACTI, &f, &one) == aiReturn_SUCCESS) fm->ior = f;
    /* the diffuse texture, a file beside the model (embedded ones, "*N", are not read) */
    struct aiString tex;
    if (aiGetMaterialTexture(am, aiTextureType_DIFFUSE, 0, &tex, NULL, NULL, NULL, NULL, NULL, NULL) == aiReturn_SUCCESS &&
        tex.data[0] != '*' && !fr_scene_ref_path(path, tex.data, fm->map_kd, sizeof fm->map_kd))
      fm->map_kd[0] = 0;
  }
  fr_error e = sc->mRootNode ? add_node(sc, sc->mRootNode, NULL, matmap, m, 0) : FR_OK;
  free(matmap);
  return e;
}

/* The import itself, in the child; NULL with *e set where frusta's own
 * reading failed (a .zst that does not inflate), with *e FR_OK where
 * Assimp's did. */
static const struct aiScene *import_scene(const char *path, fr_error *e) {
  *e = FR_OK;
  unsigned flags = aiProcess_Triangulate | aiProcess_SortByPType;
  struct aiFileIO io;
  fr_assimp_fs fs = {path, path, NULL, 0};
  if (!fr_has_suffix(path, ".zst")) {
    fr_assimp_files(&io, &fs);
    return aiImportFileEx(path, flags, &io);
  }
  /* a .zst: Assimp opens the inflated bytes by the name without .zst (its
   * extension picks the importer); what they name still resolves inside
   * the scene's folder */
  char *data, name[4096];
  size_t size;
  if ((*e = fr_read_file(path, &data, &size))) return NULL;
  snprintf(name, sizeof name, "%.*s", (int)(strlen(path) - 4), path);
  fs = (fr_assimp_fs){path, name, data, size};
  fr_assimp_files(&io, &fs);
  const struct aiScene *sc = aiImportFileEx(name, flags, &io);
  free(data); /* the child ends soon after; Assimp holds no pointer into it */
  return sc;
}

/* The pipe's records: a status, then the message or the mesh. */
static int put(int fd, const void *p, size_t n) {
  const char *c = p;
  while (n) {
    ssize_t w = write(fd, c, n);
    if (w < 0 && errno == EINTR) continue;
    if (w <= 0) return 0;
    c += w;
    n -= (size_t)w;
  }
  return 1;
}

static int get(int fd, void *p, size_t n) {
  char *c = p;
  while (n) {
    ssize_t r = read(fd, c, n);
    if (r < 0 && errno == EINTR) continue;
    if (r <= 0) return 0;
    c += r;
    n -= (size_t)r;
  }
  return 1;
}

static void send_mesh(int fd, fr_error e, const fr_mesh *m) {
  const int32_t status = (int32_t)e;
  if (!put(fd, &status, sizeof status)) return;
  if (e) {
    const char *msg = fr_last_error();
    const uint32_t n = (uint32_t)strlen(msg);
    if (put(fd, &n, sizeof n)) put(fd, msg, n);
    return;
  }
  const uint64_t counts[3] = {m->nverts, m->ntris, m->nmats};
  /* flags: 1 per-triangle materials follow the indices, 2 per-vertex
   * normals follow the materials, 4 per-vertex texture coordinates follow */
  const uint8_t has_mat = m->mat != NULL, has_nrm = m->nverts && m->nrm.n == m->nverts, has_uv = m->nverts && m->uv.n == m->nverts;
  const uint8_t flags = (uint8_t)(has_mat | has_nrm << 1 | has_uv << 2);
  if (put(fd, counts, sizeof counts) && put(fd, &flags, 1) && put(fd, m->pos, m->nverts * 3 * sizeof(float)) &&
      put(fd, m->idx, m->ntris * 3 * sizeof(uint32_t)) && (!has_mat || put(fd, m->mat, m->ntris * sizeof(uint32_t))) &&
      put(fd, m->mats, m->nmats * sizeof(fr_material)) && (!has_nrm || put(fd, m->nrm.val, m->nrm.n * 3 * sizeof(float))) &&
      has_uv)
    put(fd, m->uv.val, m->uv.n * 2 * sizeof(float));
}

static void limit_child(size_t file_bytes) {
  alarm(ASSIMP_SECONDS); /* a child that blocks */
  struct rlimit cpu = {ASSIMP_SECONDS, ASSIMP_SECONDS + 1};
  setrlimit(RLIMIT_CPU, &cpu); /* a child that spins */
#ifndef FR_ASAN /* AddressSanitizer's shadow memory would not fit */
  long pages = 0;
  FILE *f = fopen("/proc/self/statm", "r");
  if (f) {
    if (fscanf(f, "%ld", &pages) != 1) pages = 0;
    fclose(f);
  }
  const size_t mapped = (size_t)pages * (size_t)sysconf(_SC_PAGESIZE);
  const size_t allow = ASSIMP_MEMORY_BASE + (file_bytes < ((size_t)1 << 34) ? file_bytes * ASSIMP_MEMORY_PER_BYTE
                                                                            : ((size_t)1 << 40));
  struct rlimit as = {mapped + allow, mapped + allow};
  setrlimit(RLIMIT_AS, &as);
#endif
}

static _Noreturn void run_child(int fd, const char *path) {
  const int devnull = open("/dev/null", O_WRONLY);
  if (devnull >= 0) { dup2(devnull, 1); dup2(devnull, 2); } /* Assimp's chatter is not ours */
  struct stat st;
  limit_child(stat(path, &st) == 0 && st.st_size > 0 ? (size_t)st.st_size : 0);
  fr_mesh m;
  fr_mesh_init(&m);
  fr_error e;
  const struct aiScene *sc = import_scene(path, &e);
  if (sc) e = convert(sc, path, &m);
  else if (!e) e = fr_fail(FR_ERR_FORMAT, "%s: %s", path, aiGetErrorString());
  send_mesh(fd, e, &m);
  _exit(0);
}

/* The mesh from the pipe, read as it comes, so that memory follows what the
 * child really sent. *broke: the pipe ended early (the child died). */
/* A texture the child names must be a file in the model's folder: the
 * child reads untrusted bytes, so its word is checked again here. */
static void confine_texture(const char *model, char *tex, size_t cap) {
  if (!tex[0]) return;
  const char *slash = strrchr(model, '/');
  const size_t dir = slash ? (size_t)(slash - model) + 1 : 0;
  char rel[512], out[512];
  if (strncmp(tex, model, dir) != 0 || strlen(tex + dir) >= sizeof rel) { tex[0] = 0; return; }
  snprintf(rel, sizeof rel, "%s", tex + dir);
  if (!fr_scene_ref_path(model, rel, out, sizeof out)) { tex[0] = 0; return; }
  snprintf(tex, cap, "%s", out);
}

static fr_error receive_mesh(int fd, const char *path, fr_mesh *m, int *broke) {
#define BROKE (*broke = 1, FR_ERR_IO)
  int32_t status;
  if (!get(fd, &status, sizeof status)) return BROKE;
  if (status) {
    uint32_t n = 0;
    char msg[512] = "";
    if (get(fd, &n, sizeof n) && n < sizeof msg) get(fd, msg, n);
    return fr_fail((fr_error)status, "%s", msg[0] ? msg : "Assimp could not read the file");
  }
  uint64_t counts[3];
  uint8_t flags;
  if (!get(fd, counts, sizeof counts) || !get(fd, &flags, 1)) return BROKE;
  const int has_mat = flags & 1, has_nrm = (flags >> 1) & 1, has_uv = (flags >> 2) & 1;
  if (counts[0] > 0xFFFFFFF0u || counts[1] > 0xFFFFFFF0u || counts[2] > 0xFFFFFFu)
    return fr_fail(FR_ERR_FORMAT, "%s: too large", path);
  for (uint64_t i = 0; i < counts[0]; i++) {
    float v[3];
    if (!get(fd, v, sizeof v)) return BROKE;
    fr_error e = fr_mesh_add_vertex(m, v[0], v[1], v[2]);
    if (e) return e;
  }
  uint32_t *idx = malloc(counts[1] ? counts[1] * 3 * sizeof *idx : 1), *mat = NULL;
  if (!idx) return fr_fail(FR_ERR_NOMEM, "%s: out of memory", path);
  fr_error e = get(fd, idx, counts[1] * 3 * sizeof *idx) ? FR_OK : BROKE;
  if (!e && has_mat && !(mat = malloc(counts[1] ? counts[1] * sizeof *mat : 1))) e = fr_fail(FR_ERR_NOMEM, "out of memory");
  if (!e && has_mat && !get(fd, mat, counts[1] * sizeof *mat)) e = BROKE;
  for (uint64_t i = 0; i < counts[2] && !e; i++) {
    fr_material fm;
    uint32_t k;
    if (!get(fd, &fm, sizeof fm)) { e = BROKE; break; }
    fm.name[sizeof fm.name - 1] = 0;
    fm.map_kd[sizeof fm.map_kd - 1] = 0;
    confine_texture(path, fm.map_kd, sizeof fm.map_kd);
    if (!(e = fr_mesh_material(m, fm.name, &k))) m->mats[k] = fm;
  }
  for (uint64_t i = 0; i < counts[0] && has_nrm && !e; i++) {
    float n[3];
    e = get(fd, n, sizeof n) ? fr_mesh_add_normal(m, n[0], n[1], n[2]) : BROKE;
  }
  for (uint64_t i = 0; i < counts[0] && has_uv && !e; i++) {
    float st[2];
    e = get(fd, st, sizeof st) ? fr_mesh_add_uv(m, st[0], st[1]) : BROKE;
  }
  for (uint64_t t = 0; t < counts[1] && !e; t++) {
    const uint32_t *ix = idx + 3 * t;
    e = fr_mesh_add_triangle(m, ix[0], ix[1], ix[2], mat ? mat[t] : FR_INVALID_ID);
    if (!e && has_nrm && ix[0] < m->nrm.n && ix[1] < m->nrm.n && ix[2] < m->nrm.n) {
      e = fr_mesh_set_normals(m, m->ntris - 1, ix[0], ix[1], ix[2]);
      if (!e && !fr_mesh_has_normals(m, m->ntris - 1)) /* a mesh without normals among ones with */
        e = fr_mesh_set_normals(m, m->ntris - 1, FR_INVALID_ID, FR_INVALID_ID, FR_INVALID_ID);
    }
    if (!e && has_uv && ix[0] < m->uv.n && ix[1] < m->uv.n && ix[2] < m->uv.n) e = fr_mesh_set_uvs(m, m->ntris - 1, ix[0], ix[1], ix[2]);
  }
  free(idx);
  free(mat);
  return e;
#undef BROKE
}

fr_error fr_import_assimp(const char *path, const char *ext, fr_mesh *m) {
  int fd[2];
  if (pipe(fd)) return fr_fail(FR_ERR_IO, "%s: pipe: %s", path, strerror(errno));
  fflush(NULL);
  pid_t pid = fork();
  if (pid < 0) {
    close(fd[0]);
    close(fd[1]);
    return fr_fail(FR_ERR_NOMEM, "%s: fork: %s", path, strerror(errno));
  }
  if (pid == 0) {
    close(fd[0]);
    run_child(fd[1], path);
  }
  close(fd[1]);
  int broke = 0;
  fr_error e = receive_mesh(fd[0], path, m, &broke);
  close(fd[0]);
  int st = 0;
  while (waitpid(pid, &st, 0) < 0 && errno == EINTR) {}
  if (!broke) return e;
  fr_mesh_free(m);
  fr_mesh_init(m);
  if (WIFSIGNALED(st)) {
    const int sig = WTERMSIG(st);
    if (sig == SIGALRM || sig == SIGXCPU)
      return fr_fail(FR_ERR_FORMAT, "%s: Assimp did not finish within %d s", path, ASSIMP_SECONDS);
    return fr_fail(FR_ERR_FORMAT, "%s: Assimp failed on this file (%s)", path, strsignal(sig));
  }
  return fr_fail(FR_ERR_FORMAT, "%s: Assimp failed on this file", path);
}
