/* Mesh files read through libassimp's C API (assimp/cimport.h): STL (ASCII
 * and binary), OBJ, PLY, OFF, 3MF, glTF... The scene's node transforms are
 * applied (aiProcess_PreTransformVertices), polygons triangulated; points
 * and lines are left out. Without libassimp (SPH_HAVE_ASSIMP unset) every
 * read is refused with the reason. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "scene/mesh.h"

#ifdef SPH_HAVE_ASSIMP
#include <assimp/cimport.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

static const unsigned read_flags =
    aiProcess_Triangulate | aiProcess_PreTransformVertices;

static sph_status from_scene(const struct aiScene *sc, const char *path,
                             double **tri, size_t *n, sph_error *err) {
  if (!sc)
    return sph_error_set(err, SPH_ERR_IO, "%s: not a mesh sph can read (%s)",
                         path, aiGetErrorString());
  size_t count = 0;
  for (unsigned k = 0; k < sc->mNumMeshes; ++k)
    for (unsigned f = 0; f < sc->mMeshes[k]->mNumFaces; ++f)
      count += sc->mMeshes[k]->mFaces[f].mNumIndices == 3;
  if (count == 0) {
    aiReleaseImport(sc);
    return sph_error_set(err, SPH_ERR_IO, "%s: the mesh has no triangles",
                         path);
  }
  double *t = malloc(9 * count * sizeof *t);
  if (!t) {
    aiReleaseImport(sc);
    return sph_error_set(err, SPH_ERR_NOMEM, "mesh %s", path);
  }
  size_t q = 0;
  for (unsigned k = 0; k < sc->mNumMeshes; ++k) {
    const struct aiMesh *m = sc->mMeshes[k];
    for (unsigned f = 0; f < m->mNumFaces; ++f) {
      const struct aiFace *face = &m->mFaces[f];
      if (face->mNumIndices != 3)
        continue;
      for (int c = 0; c < 3; ++c) {
        unsigned i = face->mIndices[c];
        if (i >= m->mNumVertices) {
          free(t);
          aiReleaseImport(sc);
          return sph_error_set(err, SPH_ERR_IO,
                               "%s: a face names vertex %u of %u", path, i,
                               m->mNumVertices);
        }
        t[q++] = m->mVertices[i].x;
        t[q++] = m->mVertices[i].y;
        t[q++] = m->mVertices[i].z;
      }
    }
  }
  aiReleaseImport(sc);
  *tri = t;
  *n = count;
  return SPH_OK;
}
#endif

sph_status sph_mesh_read(const char *path, double **tri, size_t *n,
                         sph_error *err) {
  *tri = NULL;
  *n = 0;
  struct stat st;
  if (stat(path, &st) != 0)
    return sph_error_set(err, SPH_ERR_IO, "%s: no such file", path);
  if (!S_ISREG(st.st_mode))
    return sph_error_set(err, SPH_ERR_IO, "%s: not a file", path);
  if (st.st_size == 0)
    return sph_error_set(err, SPH_ERR_IO, "%s: the file is empty", path);
#ifdef SPH_HAVE_ASSIMP
  return from_scene(aiImportFile(path, read_flags), path, tri, n, err);
#else
  return sph_error_set(err, SPH_ERR_IO,
                       "%s: this sph was built without libassimp, which "
                       "reads meshes (bootstrap.sh installs libassimp-dev; "
                       "then configure and build again)",
                       path);
#endif
}

sph_status sph_mesh_read_memory(const void *bytes, size_t len, const char *hint,
                                double **tri, size_t *n, sph_error *err) {
  *tri = NULL;
  *n = 0;
#ifdef SPH_HAVE_ASSIMP
  if (len == 0 || len > 0xffffffffu)
    return sph_error_set(err, SPH_ERR_IO, "<memory>: empty or too large");
  return from_scene(
      aiImportFileFromMemory(bytes, (unsigned)len, read_flags, hint),
      "<memory>", tri, n, err);
#else
  (void)bytes;
  (void)len;
  (void)hint;
  return sph_error_set(err, SPH_ERR_IO, "built without libassimp");
#endif
}
