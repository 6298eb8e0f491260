/* Gmsh's C API, loaded on first use (PeriGmshLoad, src/disc/gmsh_api.c) rather than linked:
 * libgmsh brings OpenCASCADE and some fifty other libraries, 36 MB resident in every process
 * (of a runtime floor of 89 MB), which only a run that reads particles.mesh needs (issue 29,
 * item 3: the memory per rank). The call sites keep Gmsh's own names, defined here as calls
 * through the table. */
#pragma once

#include <gmshc.h>
#include <petscsys.h>

#define PERI_GMSH_FUNCTIONS(X)         \
  X(Initialize)                        \
  X(Finalize)                          \
  X(Free)                              \
  X(OptionSetNumber)                   \
  X(Clear)                             \
  X(Open)                              \
  X(Write)                             \
  X(ModelMeshRefine)                   \
  X(ModelMeshGetNodesForPhysicalGroup) \
  X(ModelMeshGetNodes)                 \
  X(ModelMeshGetElements)              \
  X(ModelMeshGetElementTypes)          \
  X(ModelMeshGetElementProperties)     \
  X(ModelMeshGenerate)                 \
  X(ModelGetPhysicalName)              \
  X(ModelGetPhysicalGroups)            \
  X(ModelGetEntitiesForPhysicalGroup)  \
  X(LoggerGetLastError)

#define PERI_GMSH_FIELD(f) __typeof__(gmsh##f) *f;
typedef struct {
  PERI_GMSH_FUNCTIONS(PERI_GMSH_FIELD)
} PeriGmshTable;
#undef PERI_GMSH_FIELD

PETSC_EXTERN PeriGmshTable  PeriGmsh;
PETSC_EXTERN PetscErrorCode PeriGmshLoad(void);

#define gmshInitialize                        (*PeriGmsh.Initialize)
#define gmshFinalize                          (*PeriGmsh.Finalize)
#define gmshFree                              (*PeriGmsh.Free)
#define gmshOptionSetNumber                   (*PeriGmsh.OptionSetNumber)
#define gmshClear                             (*PeriGmsh.Clear)
#define gmshOpen                              (*PeriGmsh.Open)
#define gmshWrite                             (*PeriGmsh.Write)
#define gmshModelMeshRefine                   (*PeriGmsh.ModelMeshRefine)
#define gmshModelMeshGetNodesForPhysicalGroup (*PeriGmsh.ModelMeshGetNodesForPhysicalGroup)
#define gmshModelMeshGetNodes                 (*PeriGmsh.ModelMeshGetNodes)
#define gmshModelMeshGetElements              (*PeriGmsh.ModelMeshGetElements)
#define gmshModelMeshGetElementTypes          (*PeriGmsh.ModelMeshGetElementTypes)
#define gmshModelMeshGetElementProperties     (*PeriGmsh.ModelMeshGetElementProperties)
#define gmshModelMeshGenerate                 (*PeriGmsh.ModelMeshGenerate)
#define gmshModelGetPhysicalName              (*PeriGmsh.ModelGetPhysicalName)
#define gmshModelGetPhysicalGroups            (*PeriGmsh.ModelGetPhysicalGroups)
#define gmshModelGetEntitiesForPhysicalGroup  (*PeriGmsh.ModelGetEntitiesForPhysicalGroup)
#define gmshLoggerGetLastError                (*PeriGmsh.LoggerGetLastError)
