/*
 * Everything that is not PLY or OBJ goes through Assimp's C API (glTF, FBX,
 * 3DS, ...). Meshes are flattened with their node transforms; triangle numbers
 * follow Assimp's mesh order. A .zst file is inflated and handed over from
 * memory (formats with external buffers then need the uncompressed file).
 */
#include <stdio.h>
#include <assimp/cimport.h>
#include <assimp/material.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <stdlib.h>
#include <string.h>
#include "base/error.h"
#include "io/file_read.h"
#include "io/import.h"

/* key, type, index: the triple Assimp's AI_MATKEY_* macros expand to */
static void copy_color(const struct aiMaterial *am, const char *key, unsigned type, unsigned index, float out[3]) {
  struct aiColor4D c;
  if (aiGetMaterialColor(am, key, type, index, &c) == aiReturn_SUCCESS) { out[0] = c.r; out[1] = c.g; out[2] = c.b; }
}

static fr_error convert(const struct aiScene *sc, fr_mesh *m) {
  uint32_t *matmap = calloc(sc->mNumMaterials + 1, sizeof(uint32_t));
  if (!matmap) return fr_fail(FR_ERR_NOMEM, "out of memory");
  for (unsigned i = 0; i < sc->mNumMaterials; i++) {
    const struct aiMaterial *am = sc->mMaterials[i];
    struct aiString name;
    char nm[64];
    if (aiGetMaterialString(am, AI_MATKEY_NAME, &name) == aiReturn_SUCCESS) snprintf(nm, sizeof nm, "%s", name.data);
    else snprintf(nm, sizeof nm, "material_%u", i);
    fr_error e = fr_mesh_material(m, nm, &matmap[i]);
    if (e) { free(matmap); return e; }
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
  }
  fr_error e = FR_OK;
  for (unsigned i = 0; i < sc->mNumMeshes && !e; i++) {
    const struct aiMesh *am = sc->mMeshes[i];
    if (m->nverts + am->mNumVertices >= 0xFFFFFFF0u) { e = fr_fail(FR_ERR_UNSUPPORTED, "too many vertices"); break; }
    uint32_t base = (uint32_t)m->nverts;
    for (unsigned v = 0; v < am->mNumVertices && !e; v++)
      e = fr_mesh_add_vertex(m, am->mVertices[v].x, am->mVertices[v].y, am->mVertices[v].z);
    uint32_t mat = am->mMaterialIndex < sc->mNumMaterials ? matmap[am->mMaterialIndex] : FR_INVALID_ID;
    for (unsigned f = 0; f < am->mNumFaces && !e; f++) {
      const struct aiFace *face = &am->mFaces[f];
      for (unsigned j = 2; j < face->mNumIndices && !e; j++)
        e = fr_mesh_add_triangle(m, base + face->mIndices[0], base + face->mIndices[j - 1], base + face->mIndices[j], mat);
    }
  }
  free(matmap);
  return e;
}

fr_error fr_import_assimp(const char *path, const char *ext, fr_mesh *m) {
  unsigned flags = aiProcess_Triangulate | aiProcess_PreTransformVertices | aiProcess_SortByPType;
  const struct aiScene *sc;
  if (fr_has_suffix(path, ".zst")) {
    char *data;
    size_t size;
    fr_error e = fr_read_file(path, &data, &size);
    if (e) return e;
    if (size > 0xFFFFFFFFu) { free(data); return fr_fail(FR_ERR_UNSUPPORTED, "%s: too large for Assimp", path); }
    sc = aiImportFileFromMemory(data, (unsigned)size, flags, ext);
    free(data);
  } else {
    sc = aiImportFile(path, flags);
  }
  if (!sc) return fr_fail(FR_ERR_FORMAT, "%s: %s", path, aiGetErrorString());
  fr_error e = convert(sc, m);
  aiReleaseImport(sc);
  return e;
}
