/* Loads Gmsh's C API on first use (include/perilin/private/gmsh_api.h says why). */
#include "perilin/private/disc.h"
#include <dlfcn.h>

#include "perilin/private/gmsh_api.h"

#ifndef PERI_GMSH_LIBRARY
#  define PERI_GMSH_LIBRARY "libgmsh.so"
#endif

PeriGmshTable PeriGmsh;

/*@C
  PeriGmshLoad - opens Gmsh's library (the one perilin was built against, PERI_GMSH_LIBRARY) and
  finds its functions, once. Not collective.
@*/
PetscErrorCode PeriGmshLoad(void)
{
  static void *lib = NULL;
  void        *f;

  PetscFunctionBeginUser;
  if (lib) PetscFunctionReturn(PETSC_SUCCESS);
  lib = dlopen(PERI_GMSH_LIBRARY, RTLD_NOW | RTLD_LOCAL);
  PetscCheck(lib, PETSC_COMM_SELF, PETSC_ERR_LIB, "particles.mesh needs Gmsh, which cannot be loaded: %s (install Debian's libgmsh4.8)", dlerror());
#define PERI_GMSH_FIND(name)                                                                                           \
  f = dlsym(lib, "gmsh" #name);                                                                                        \
  PetscCheck(f, PETSC_COMM_SELF, PETSC_ERR_LIB, "Gmsh's library %s has no function gmsh%s", PERI_GMSH_LIBRARY, #name); \
  *(void **)&PeriGmsh.name = f;
  PERI_GMSH_FUNCTIONS(PERI_GMSH_FIND)
#undef PERI_GMSH_FIND
  PetscFunctionReturn(PETSC_SUCCESS);
}
