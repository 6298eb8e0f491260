/* Child processes that run perilin's Python helpers: the run's pictures (src/output/plots.c) and
 * the conversion of Abaqus and Exodus meshes (src/disc/mesh.c). A helper is found by its path, run
 * with its output into a log, and stopped after a timeout: nothing it does can hang the run. */
#define _GNU_SOURCE
#include "perilin/private/sys.h"

#include <errno.h>
#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

extern char **environ;

/*@C
  PeriChildScript - a helper script: $env (when set), else source (the source tree's, a build),
  else installed; NULL when none is readable. Not collective.
@*/
const char *PeriChildScript(const char env[], const char source[], const char installed[])
{
  const char *e = getenv(env);

  if (e && e[0]) return e;
  if (source[0] && access(source, R_OK) == 0) return source;
  if (installed[0] && access(installed, R_OK) == 0) return installed;
  return NULL;
}

/*@C
  PeriChildPython - the interpreter: $PERILIN_PYTHON, else the one CMake found able to import what
  the helper needs (the first python3 on PATH may be a pyenv or venv without it). Not collective.
@*/
const char *PeriChildPython(const char found[])
{
  const char *env = getenv("PERILIN_PYTHON");

  return env && env[0] ? env : found;
}

/* The last non-empty line of the child's log, as the reason it failed. */
static void LastLine(const char log[], char reason[], size_t len)
{
  char  line[512];
  FILE *fp = fopen(log, "r");

  if (!fp) return;
  while (fgets(line, sizeof(line), fp)) {
    line[strcspn(line, "\n")] = 0;
    if (line[0]) snprintf(reason, len, "%s", line);
  }
  fclose(fp);
}

/*@C
  PeriChildRun - runs argv (argv[1]: the script, for messages) with stdout and stderr into log and
  stdin from /dev/null; 0 when it exited 0 within timeout seconds, else 1 with reason: the log's
  last line, or why it could not run or was stopped. Not collective.
@*/
int PeriChildRun(char *const argv[], const char log[], int timeout, char reason[], size_t len)
{
  posix_spawn_file_actions_t fa;
  pid_t                      pid;
  int                        status = 0, err;
  const struct timespec      tick   = {0, 20000000};

  posix_spawn_file_actions_init(&fa);
  posix_spawn_file_actions_addopen(&fa, 1, log, O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_adddup2(&fa, 1, 2);
  posix_spawn_file_actions_addopen(&fa, 0, "/dev/null", O_RDONLY, 0);
  err = posix_spawnp(&pid, argv[0], &fa, NULL, argv, environ);
  posix_spawn_file_actions_destroy(&fa);
  if (err) {
    snprintf(reason, len, "cannot run %s: %s", argv[0], strerror(err));
    return 1;
  }
  for (int t = 0; t < timeout * 50; t++) {
    pid_t w = waitpid(pid, &status, WNOHANG);
    if (w == pid) {
      if (WIFEXITED(status) && WEXITSTATUS(status) == 0) return 0;
      snprintf(reason, len, "%s %s", argv[1], WIFEXITED(status) ? "failed" : "was killed by a signal");
      LastLine(log, reason, len);
      return 1;
    }
    if (w < 0 && errno != EINTR) break;
    nanosleep(&tick, NULL);
  }
  kill(pid, SIGKILL);
  (void)waitpid(pid, &status, 0);
  snprintf(reason, len, "%s took more than %d s and was stopped", argv[1], timeout);
  return 1;
}
