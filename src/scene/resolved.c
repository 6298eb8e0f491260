/* The resolved scene: the scene as the run used it, written back as YAML (scene.yaml of every
 * output set, docs/summary.md); given back to perilin, it reproduces the run. It is the file's tree
 * after the option overrides, with what the readers resolved beyond the file merged in
 * (scene->resolved): the declared defaults the getters applied, input files made absolute so that
 * the copy may be read from the output directory, the output directory.
 * Values are written as the text the run parsed (the file's, an option's or the declaration's), not
 * printed again from the numbers: read again, the text gives the same numbers bit for bit, and a
 * fraction such as 1/3 (an exact Poisson ratio) stays as the user wrote it. */
#include "perilin/private/scene_file.h"
#include <yaml.h>

#include <sys/stat.h>

/* What a path that is no regular file is, or NULL for a regular file or none at all (whose open
 * fails with its own message). */
static const char *NotRegular(const char path[])
{
  struct stat st;

  if (stat(path, &st)) return NULL;
  if (S_ISREG(st.st_mode)) return NULL;
  if (S_ISDIR(st.st_mode)) return "a directory";
  if (S_ISFIFO(st.st_mode)) return "a pipe (FIFO)";
  if (S_ISCHR(st.st_mode)) return "a character device";
  if (S_ISBLK(st.st_mode)) return "a block device";
  if (S_ISSOCK(st.st_mode)) return "a socket";
  return "not a regular file";
}

/*@C
  PeriSceneGetPath - the file named by map.key, relative to the scene file's directory unless
  absolute (particles.file, particles.mesh); the resolved scene holds it absolute. *found (may be
  NULL) says whether it was given; path is left alone otherwise. Every such key names an input
  file, which must be a regular file: a device (/dev/zero) or a pipe may never end, and opening a
  FIFO blocks until a writer comes, so they are refused by stat before any open. Not collective.
@*/
PetscErrorCode PeriSceneGetPath(PeriScene scene, PeriNode map, const char key[], PetscBool required, char path[], size_t size, PetscBool *found)
{
  char      name[PETSC_MAX_PATH_LEN];
  PetscBool has;

  PetscFunctionBeginUser;
  PetscCall(PeriSceneGetString(scene, map, key, required, name, sizeof(name), &has));
  if (found) *found = has;
  if (!has) PetscFunctionReturn(PETSC_SUCCESS);
  if (name[0] == '/')
    PetscCall(PetscStrncpy(path, name, size));
  else
    PetscCall(PetscSNPrintf(path, size, "%s/%s", scene->dir, name));
  PetscCall(PeriSceneResolvePath(scene, map, key, path));
  PeriInputCheck(!NotRegular(path), scene, map, key, "%s is %s: give a regular file (a device or a pipe may never end)", path, NotRegular(path));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Emits ev (which libyaml then owns and frees). */
static PetscErrorCode Emit(yaml_emitter_t *e, yaml_event_t *ev, int ok)
{
  PetscFunctionBeginUser;
  PetscCheck(ok && yaml_emitter_emit(e, ev), PETSC_COMM_SELF, PETSC_ERR_FILE_WRITE, "writing the resolved scene failed: %s", e->problem ? e->problem : "libyaml error");
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* A plain scalar where YAML allows one, else quoted: the reader takes the text either way. */
static PetscErrorCode Scalar(yaml_emitter_t *e, const char text[])
{
  yaml_event_t ev;

  PetscFunctionBeginUser;
  PetscCall(Emit(e, &ev, yaml_scalar_event_initialize(&ev, NULL, NULL, (yaml_char_t *)text, (int)strlen(text), 1, 1, YAML_ANY_SCALAR_STYLE)));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The child of node (NULL: none) with the key of other. */
static PeriNode Match(PeriNode node, PeriNode other)
{
  for (PetscInt k = 0; node && k < node->n; k++)
    if (!strcmp(node->child[k]->key, other->key)) return node->child[k];
  return NULL;
}

/* Whether node is a list of values (or empty): written as a flow list, [0, 1], as scenes are. */
static PetscBool IsValueList(PeriNode node)
{
  for (PetscInt k = 0; k < node->n; k++)
    if (node->child[k]->kind != PERI_NODE_SCALAR) return PETSC_FALSE;
  return PETSC_TRUE;
}

static PetscErrorCode EmitNode(yaml_emitter_t *, PeriNode, PeriNode);

/* The children of a (the file's, in its order), each merged with b's of the same key, then b's
 * children the file lacks (the defaults, in the order the run read them). */
static PetscErrorCode EmitChildren(yaml_emitter_t *e, PeriNode a, PeriNode b, PetscBool keys)
{
  PetscFunctionBeginUser;
  for (PetscInt k = 0; a && k < a->n; k++) {
    if (keys) PetscCall(Scalar(e, a->child[k]->key));
    PetscCall(EmitNode(e, a->child[k], Match(b, a->child[k])));
  }
  for (PetscInt k = 0; b && k < b->n; k++) {
    if (Match(a, b->child[k])) continue;
    if (keys) PetscCall(Scalar(e, b->child[k]->key));
    PetscCall(EmitNode(e, NULL, b->child[k]));
  }
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The file's node a merged with the resolved node b of the same path (either may be NULL). */
static PetscErrorCode EmitNode(yaml_emitter_t *e, PeriNode a, PeriNode b)
{
  PeriNode     n = a ? a : b;
  yaml_event_t ev;

  PetscFunctionBeginUser;
  if (n->kind == PERI_NODE_SCALAR) {
    PetscCall(Scalar(e, b && b->kind == PERI_NODE_SCALAR ? b->value : a->value));
  } else if (n->kind == PERI_NODE_SEQ) {
    PetscCall(Emit(e, &ev, yaml_sequence_start_event_initialize(&ev, NULL, NULL, 1, IsValueList(n) ? YAML_FLOW_SEQUENCE_STYLE : YAML_BLOCK_SEQUENCE_STYLE)));
    PetscCall(EmitChildren(e, a, b, PETSC_FALSE));
    PetscCall(Emit(e, &ev, yaml_sequence_end_event_initialize(&ev)));
  } else {
    PetscCall(Emit(e, &ev, yaml_mapping_start_event_initialize(&ev, NULL, NULL, 1, YAML_BLOCK_MAPPING_STYLE)));
    PetscCall(EmitChildren(e, a, b, PETSC_TRUE));
    PetscCall(Emit(e, &ev, yaml_mapping_end_event_initialize(&ev)));
  }
  PetscFunctionReturn(PETSC_SUCCESS);
}

static PetscErrorCode EmitDocument(yaml_emitter_t *e, PeriScene scene)
{
  yaml_event_t ev;

  PetscFunctionBeginUser;
  PetscCall(Emit(e, &ev, yaml_stream_start_event_initialize(&ev, YAML_UTF8_ENCODING)));
  PetscCall(Emit(e, &ev, yaml_document_start_event_initialize(&ev, NULL, NULL, NULL, 1)));
  PetscCall(EmitNode(e, scene->root, scene->resolved));
  PetscCall(Emit(e, &ev, yaml_document_end_event_initialize(&ev, 1)));
  PetscCall(Emit(e, &ev, yaml_stream_end_event_initialize(&ev)));
  PetscCheck(yaml_emitter_flush(e), PETSC_COMM_SELF, PETSC_ERR_FILE_WRITE, "writing the resolved scene failed: %s", e->problem ? e->problem : "libyaml error");
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriSceneWriteResolved - writes to fp the lines of header as YAML comments, then the resolved
  scene (libyaml's emitter: block mappings, lists of values in flow style, lines never folded).
  Not collective.
@*/
PetscErrorCode PeriSceneWriteResolved(PeriScene scene, const char header[], FILE *fp)
{
  yaml_emitter_t e;
  PetscErrorCode ierr;

  PetscFunctionBeginUser;
  for (const char *line = header; line && *line;) {
    size_t n = strcspn(line, "\n");
    fprintf(fp, "#%s%.*s\n", n ? " " : "", (int)n, line);
    line += n + (line[n] == '\n');
  }
  PetscCheck(yaml_emitter_initialize(&e), PETSC_COMM_SELF, PETSC_ERR_LIB, "libyaml could not initialize");
  yaml_emitter_set_output_file(&e, fp);
  yaml_emitter_set_unicode(&e, 1);
  yaml_emitter_set_width(&e, -1);
  ierr = EmitDocument(&e, scene);
  yaml_emitter_delete(&e);
  PetscCall(ierr);
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriSceneFingerprint - a 64-bit hash (FNV-1a) of the resolved scene as it stands, without its
  output section (where and what a run writes does not change what it computes): two runs with the
  same fingerprint read the same keys with the same values, so a checkpoint of one can continue the
  other. Not collective; every rank computes the same.
@*/
PetscErrorCode PeriSceneFingerprint(PeriScene scene, PetscInt64 *hash)
{
  char          *text = NULL;
  size_t         len  = 0;
  FILE          *fp   = open_memstream(&text, &len);
  PetscBool      skip = PETSC_FALSE;
  PetscErrorCode ierr;

  PetscFunctionBeginUser;
  PetscCheck(fp, PETSC_COMM_SELF, PETSC_ERR_MEM, "cannot open a memory stream for the scene's fingerprint");
  ierr = PeriSceneWriteResolved(scene, NULL, fp);
  fclose(fp);
  if (ierr) free(text);
  PetscCall(ierr);
  *hash = (PetscInt64)0xcbf29ce484222325ULL;
  /* line by line: the top-level section output: and its indented lines are left out */
  for (const char *line = text; line && *line;) {
    size_t n = strcspn(line, "\n");
    if (line[0] != ' ' && line[0] != '-') skip = (PetscBool)!strncmp(line, "output:", 7);
    for (size_t k = 0; k < n && !skip; k++) *hash = (PetscInt64)(((unsigned long long)*hash ^ (unsigned char)line[k]) * 0x100000001b3ULL);
    line += n + (line[n] == '\n');
  }
  free(text);
  PetscFunctionReturn(PETSC_SUCCESS);
}
