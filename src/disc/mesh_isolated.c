/* Meshing a .geo in a child process, and Gmsh's last error message. Gmsh 4.8 ends the whole process on some errors its C API
 * does not return: a MathEval size field with a function it cannot parse (Rand, say) throws a C++
 * exception inside an OpenMP region, and std::terminate aborts (SIGABRT) with a backtrace and no
 * message a user can act on. A forked child meshes the model the parent opened and writes it to a
 * scratch .msh; the parent reads that, or reports how the child ended. */
#include "perilin/private/disc.h"
#include "perilin/private/gmsh_api.h"
#include <errno.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <unistd.h>

/*@C
  PeriGmshLastError - Gmsh's last error message, for errors that name the file. Not collective.
@*/
void PeriGmshLastError(char msg[], size_t size)
{
  char *e    = NULL;
  int   ierr = 0;

  gmshLoggerGetLastError(&e, &ierr);
  (void)PetscStrncpy(msg, !ierr && e && e[0] ? e : "unknown Gmsh error", size);
  if (e) gmshFree(e);
}

/* The child: default signal handling (not PETSc's or perilin's, which would act for the run),
 * Gmsh's messages off, the mesh generated and written to msh; its error message into log. Never
 * returns. */
static void MeshInChild(PetscInt dim, PetscReal lc, const char msh[], const char log[])
{
  const int sigs[] = {SIGABRT, SIGSEGV, SIGBUS, SIGFPE, SIGILL, SIGTERM, SIGINT, SIGHUP};
  int       ierr   = 0;
  char      msg[512];

  for (size_t s = 0; s < sizeof(sigs) / sizeof(sigs[0]); s++) (void)signal(sigs[s], SIG_DFL);
  gmshOptionSetNumber("Mesh.MeshSizeMax", lc, &ierr);
  gmshModelMeshGenerate((int)dim, &ierr);
  if (!ierr) gmshWrite(msh, &ierr);
  if (ierr) {
    FILE *f = fopen(log, "w");
    PeriGmshLastError(msg, sizeof(msg));
    if (f) {
      (void)fputs(msg, f);
      (void)fclose(f);
    }
  }
  _exit(ierr ? 1 : 0); /* no atexit handlers: MPI and PETSc belong to the parent */
}

/* How the child ended, as a sentence (empty when it wrote its mesh). */
static void ChildEnding(int status, const char log[], char msg[], size_t size)
{
  msg[0] = 0;
  if (WIFSIGNALED(status)) {
    (void)snprintf(msg, size, "Gmsh ended with signal %d (%s) while meshing, an error its C API does not return (Gmsh 4.8 aborts so on a MathEval field whose function it cannot parse, such as Rand: use a Ball, Box or Distance field, or the .geo language's Rand in a loop)", WTERMSIG(status), strsignal(WTERMSIG(status)));
  } else if (WEXITSTATUS(status)) {
    FILE *f = fopen(log, "r");
    if (!f || !fgets(msg, (int)size, f)) (void)snprintf(msg, size, "unknown Gmsh error");
    if (f) (void)fclose(f);
  }
}

/*@C
  PeriMeshGenerateIsolated - meshes the model Gmsh has open (a .geo, path) in dim with the largest
  element size lc, in a forked child, then opens the child's mesh in its place. *ok false, with
  msg saying why, when Gmsh failed or ended the child. Not collective (rank 0 reads meshes).
@*/
PetscErrorCode PeriMeshGenerateIsolated(const char path[], PetscInt dim, PetscReal lc, PetscBool *ok, char msg[], size_t size)
{
  const char *tmp = getenv("TMPDIR");
  char        dir[PETSC_MAX_PATH_LEN], msh[PETSC_MAX_PATH_LEN + 16], log[PETSC_MAX_PATH_LEN + 16];
  int         status = 0, ierr = 0;
  pid_t       pid;

  PetscFunctionBeginUser;
  PetscCall(PetscSNPrintf(dir, sizeof(dir), "%s/perilin-geo-XXXXXX", tmp && tmp[0] ? tmp : "/tmp"));
  PetscCheck(mkdtemp(dir), PETSC_COMM_SELF, PETSC_ERR_FILE_WRITE, "cannot create a scratch directory %s to mesh %s: %s", dir, path, strerror(errno));
  PetscCall(PetscSNPrintf(msh, sizeof(msh), "%s/mesh.msh", dir));
  PetscCall(PetscSNPrintf(log, sizeof(log), "%s/log", dir));
  (void)fflush(stdout);
  (void)fflush(stderr);
  pid = fork();
  PetscCheck(pid >= 0, PETSC_COMM_SELF, PETSC_ERR_SYS, "cannot fork to mesh %s: %s", path, strerror(errno));
  if (pid == 0) MeshInChild(dim, lc, msh, log);
  while (waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  ChildEnding(status, log, msg, size);
  *ok = (PetscBool)!msg[0];
  if (*ok) {
    gmshClear(&ierr);
    if (!ierr) gmshOpen(msh, &ierr);
    if (ierr) {
      PeriGmshLastError(msg, size);
      *ok = PETSC_FALSE;
    }
  }
  (void)unlink(msh);
  (void)unlink(log);
  (void)rmdir(dir);
  PetscFunctionReturn(PETSC_SUCCESS);
}
