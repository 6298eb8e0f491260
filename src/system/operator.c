/* The matrix-free operator of bond-based models (solver.operator: matrix_free): K u applied bond by
 * bond from the few numbers that each bond's block is made of, in one of three forms:
 *   central force (pmb, npmb, cpmb): k [e e^T, -e e^T; -e e^T, e e^T], stored as w = sqrt(k) e
 *     (k the spring constant, e the unit vector), 28 bytes per bond in 3D where the assembled K
 *     holds two dim x dim blocks per bond in each of two rows (about 150 bytes);
 *   spring (the central form where every bond vector is X_j - X_i, as without periodic images,
 *     and no state terms): s = sqrt(k) / |xi| only, w = s xi formed from the coordinates gathered
 *     beside u_j (s, not k / |xi|^2: the products keep the central form's magnitudes, which a
 *     prescribed value of 1e308 taught, tests/bad_input/ranges): 12 bytes per bond (the explicit step is memory-bound, and LAMMPS keeps
 *     24 a bond: issue 37's target of its peak memory);
 *   shear (pds, 2D): [A, -A; -A, A], A = k_n e e^T + k_t t t^T, stored as A's 3 entries;
 *   micropolar (mppd, gerstle; ux, uy, theta): translations move both ends alike and the sliding
 *     sees the sum of the rotations, so the 6 x 6 block is
 *       [ A    c  -A    c ]
 *       [ c^T  a  -c^T  b ]
 *       [-A   -c   A   -c ]
 *       [ c^T  b  -c^T  a ]   stored as A (3), c (2), a and b: 7 numbers (60 bytes) against 72.
 * The form comes from the block itself (CollectBonds checks that it has it). AMG then works on an
 * assembled short-range stiffness (the bonds no longer than solver.pc_radius times their ends'
 * nearest-neighbour distance, scaled to the full family's stiffness): a few shells instead of the
 * whole horizon. */
#include "perilin/private/system.h"

/* The share of its block that a broken bond keeps in the preconditioning matrix. */
#ifndef PERI_BROKEN_SHARE
#  define PERI_BROKEN_SHARE 1e-2
#endif

/* The forms of a bond's block (top of the file), and the numbers each stores per bond. */
typedef enum {
  FORM_CENTRAL,
  FORM_SPRING,
  FORM_SHEAR,
  FORM_MICROPOLAR
} BondForm;

struct _p_PeriOperator {
  PetscInt   refct; /* the system's reference and one per shell: a reused preconditioner may keep a shell after the system rebuilt its operator */
  PetscInt   nloc, bs, nghost;
  BondForm   form;
  PetscInt   nw;  /* numbers per bond: bs (central), 1 (spring), 3 (shear), 7 (micropolar) */
  PetscInt  *ptr; /* nloc + 1: the bonds of owned particle i are ptr[i] .. ptr[i+1]-1 */
  PetscInt  *jl;  /* the other end in the local numbering: owned particles, then the ghosts */
  PetscReal *w;   /* nw per bond: sqrt(k) e; sqrt(k) / |xi|; A (xx, xy, yy); A, c (x, y), a, b */
  PetscReal *X;   /* the spring form: per particle of the local numbering its bs coordinates (xi = X_j - X_i), then bs of the product's input */
  PetscInt  *ghost;
  PetscInt  *slot; /* scenes with failure: the bond list's bond k is bond slot[k] here (-1: none) */
  /* The state terms of family models (ops.bond_state; the LPS dilatation), else NULL: per bond the
     weights toward theta_i and theta_j, np numbers: for each of the na leading states (those
     along the bond) 2 multiples of w, for each other state 2 vectors of bs numbers (the affine
     dilatation: 8 numbers in 3D where all as vectors took 12); per particle and state of the
     operator's local numbering the modulus A. A broken bond's w = 0 (and its vectors' 0) takes it
     out of both terms at once. */
  PetscReal     *p, *A;
  PetscInt       ns;          /* states per particle (the model's nstates) */
  PetscInt       na, np;      /* the leading states along the bond (the model's states_along_bonds), numbers of p per bond */
  Vec            theta;       /* ghosted, ns per particle: the states, then A theta */
  Vec            sg;          /* ghosted scratch, ns bs per particle: each state's own gradient (StateOwnGradients) */
  PeriShortRange short_range; /* the preconditioning matrix's bonds and their scales */
  Vec            xm, ym;      /* ghosted work vectors: the input with held DOFs zeroed, and K of it */
  Vec            kdiag;       /* the diagonal of K */
  PetscBool      kdiag_stale; /* bonds changed since kdiag was computed: recomputed when asked for (an explicit time loop never asks) */
};

/* One MATSHELL over the shared bond data: y = s K_m x on free DOFs, y = hd x on held ones, where
 * K_m is K with the held DOFs' rows and columns removed (MatZeroRowsColumns). */
typedef struct {
  PeriOperator op;
  PetscReal    scale;
  PetscInt     nheld;
  PetscInt    *held; /* local DOFs, sorted */
  PetscReal   *hd;   /* their diagonal values */
} Shell;

/* Whether the bonds are central springs (stored as sqrt(k) e or as sqrt(k) / |xi|). */
static inline PetscBool Central(const PeriOperator op)
{
  return (PetscBool)(op->form == FORM_CENTRAL || op->form == FORM_SPRING);
}

/* The central form: y_i += sum_b w_b (w_b . (u_i - u_j)), and the opposite at j, on the local
 * forms (owned, then ghosts). Called with a literal bs, so that the compiler unrolls the inner loops. */
static inline void BondLoop(const PeriOperator op, const PetscInt bs, const PetscScalar *x, PetscScalar *y)
{
  for (PetscInt i = 0; i < op->nloc; i++) {
    const PetscScalar *ui                = x + bs * i;
    PetscScalar        acc[PERI_MAX_DOF] = {0};
    for (PetscInt b = op->ptr[i]; b < op->ptr[i + 1]; b++) {
      const PetscReal   *w  = op->w + bs * b;
      const PetscScalar *uj = x + bs * op->jl[b];
      PetscScalar       *yj = y + bs * op->jl[b], t = 0;
      for (PetscInt d = 0; d < bs; d++) t += w[d] * (ui[d] - uj[d]);
      for (PetscInt d = 0; d < bs; d++) {
        acc[d] += t * w[d];
        yj[d] -= t * w[d];
      }
    }
    for (PetscInt d = 0; d < bs; d++) y[bs * i + d] += acc[d];
  }
}

/* The spring form: y_i += w (w . (u_i - u_j)), w = s (X_j - X_i), and the opposite at j. xu holds
 * each particle's X and u side by side (2 bs numbers), so that a bond gathers one block, not two. */
static inline void SpringLoop(const PeriOperator op, const PetscInt bs, const PetscScalar *xu, PetscScalar *y)
{
  for (PetscInt i = 0; i < op->nloc; i++) {
    const PetscScalar *Xi = xu + 2 * bs * i, *ui = Xi + bs;
    PetscScalar        acc[PERI_MAX_DOF] = {0};
    for (PetscInt b = op->ptr[i]; b < op->ptr[i + 1]; b++) {
      const PetscInt     j  = op->jl[b];
      const PetscScalar *Xj = xu + 2 * bs * j, *uj = Xj + bs;
      PetscScalar       *yj = y + bs * j, t = 0, e[PERI_MAX_DOF];
      for (PetscInt d = 0; d < bs; d++) {
        e[d] = op->w[b] * (Xj[d] - Xi[d]);
        t += e[d] * (ui[d] - uj[d]);
      }
      for (PetscInt d = 0; d < bs; d++) {
        acc[d] += t * e[d];
        yj[d] -= t * e[d];
      }
    }
    for (PetscInt d = 0; d < bs; d++) y[bs * i + d] += acc[d];
  }
}

/* The spring form's product: x beside X in op->X, then the loop. */
static void SpringProduct(const PeriOperator op, const PetscScalar *x, PetscScalar *y)
{
  const PetscInt bs = op->bs;

  for (PetscInt q = 0; q < op->nloc + op->nghost; q++)
    for (PetscInt d = 0; d < bs; d++) op->X[2 * bs * q + bs + d] = x[bs * q + d];
  if (bs == 3)
    SpringLoop(op, 3, op->X, y);
  else
    SpringLoop(op, bs, op->X, y);
}

/* The shear form in 2D: f = A (u_i - u_j) at i, -f at j. */
static void ShearLoop(const PeriOperator op, const PetscScalar *x, PetscScalar *y)
{
  for (PetscInt i = 0; i < op->nloc; i++) {
    const PetscScalar *ui = x + 2 * i;
    PetscScalar        ax = 0, ay = 0;
    for (PetscInt b = op->ptr[i]; b < op->ptr[i + 1]; b++) {
      const PetscReal   *A  = op->w + 3 * b;
      const PetscScalar *uj = x + 2 * op->jl[b];
      PetscScalar       *yj = y + 2 * op->jl[b];
      const PetscScalar  dx = ui[0] - uj[0], dy = ui[1] - uj[1];
      const PetscScalar  fx = A[0] * dx + A[1] * dy, fy = A[1] * dx + A[2] * dy;
      ax += fx;
      ay += fy;
      yj[0] -= fx;
      yj[1] -= fy;
    }
    y[2 * i] += ax;
    y[2 * i + 1] += ay;
  }
}

/* The micropolar form (ux, uy, theta): with d = u_i - u_j and s = theta_i + theta_j, the forces
 * are A d + c s at i and their opposite at j, the moments c.d + a theta_i + b theta_j at i and
 * c.d + b theta_i + a theta_j at j. */
static void MicropolarLoop(const PeriOperator op, const PetscScalar *x, PetscScalar *y)
{
  for (PetscInt i = 0; i < op->nloc; i++) {
    const PetscScalar *ui = x + 3 * i;
    PetscScalar        ax = 0, ay = 0, am = 0;
    for (PetscInt b = op->ptr[i]; b < op->ptr[i + 1]; b++) {
      const PetscReal   *w  = op->w + 7 * b;
      const PetscScalar *uj = x + 3 * op->jl[b];
      PetscScalar       *yj = y + 3 * op->jl[b];
      const PetscScalar  dx = ui[0] - uj[0], dy = ui[1] - uj[1], s = ui[2] + uj[2];
      const PetscScalar  fx = w[0] * dx + w[1] * dy + w[3] * s, fy = w[1] * dx + w[2] * dy + w[4] * s, cd = w[3] * dx + w[4] * dy;
      ax += fx;
      ay += fy;
      am += cd + w[5] * ui[2] + w[6] * uj[2];
      yj[0] -= fx;
      yj[1] -= fy;
      yj[2] += cd + w[6] * ui[2] + w[5] * uj[2];
    }
    y[3 * i] += ax;
    y[3 * i + 1] += ay;
    y[3 * i + 2] += am;
  }
}

/* The state term's first pass: theta_i += p_i s and theta_j += p_j s, s = w . (u_j - u_i), over
 * the local view (the states of ghosts and of particles with bonds elsewhere are partial). */
static inline void StateLoop(const PeriOperator op, const PetscInt bs, const PetscScalar *x, PetscScalar *th)
{
  for (PetscInt i = 0; i < op->nloc; i++) {
    const PetscScalar *ui  = x + bs * i;
    PetscScalar        acc = 0;
    for (PetscInt b = op->ptr[i]; b < op->ptr[i + 1]; b++) {
      const PetscReal   *w  = op->w + bs * b;
      const PetscScalar *uj = x + bs * op->jl[b];
      PetscScalar        t  = 0;
      for (PetscInt d = 0; d < bs; d++) t += w[d] * (uj[d] - ui[d]);
      acc += op->p[2 * b] * t;
      th[op->jl[b]] += op->p[2 * b + 1] * t;
    }
    th[i] += acc;
  }
}

/* The second pass, springs and states together: with q = A theta (complete on the local view),
 * the bond's force along w is s + p_i q_i + p_j q_j, on j, and its opposite on i. */
static inline void SpringStateLoop(const PeriOperator op, const PetscInt bs, const PetscScalar *x, const PetscScalar *q, PetscScalar *y)
{
  for (PetscInt i = 0; i < op->nloc; i++) {
    const PetscScalar *ui                = x + bs * i;
    PetscScalar        acc[PERI_MAX_DOF] = {0};
    for (PetscInt b = op->ptr[i]; b < op->ptr[i + 1]; b++) {
      const PetscReal   *w  = op->w + bs * b;
      const PetscScalar *uj = x + bs * op->jl[b];
      PetscScalar       *yj = y + bs * op->jl[b], t = 0;
      for (PetscInt d = 0; d < bs; d++) t += w[d] * (uj[d] - ui[d]);
      t += op->p[2 * b] * q[i] + op->p[2 * b + 1] * q[op->jl[b]];
      for (PetscInt d = 0; d < bs; d++) {
        acc[d] -= t * w[d];
        yj[d] += t * w[d];
      }
    }
    for (PetscInt d = 0; d < bs; d++) y[bs * i + d] += acc[d];
  }
}

/* Weight d of state s toward theta_i (side 0) or theta_j (side 1) of stored bond b. */
static inline PetscReal StateWeight(const PeriOperator op, PetscInt b, PetscInt s, PetscInt side, PetscInt d)
{
  const PetscReal *p = op->p + op->np * b;
  if (s < op->na) return p[2 * s + side] * op->w[op->bs * b + d];
  return p[2 * op->na + (2 * (s - op->na) + side) * op->bs + d];
}

/* Whether the product takes the general loops (several states, or states off the bond). */
static inline PetscBool StatesMixed(const PeriOperator op)
{
  return (PetscBool)(op->ns != 1 || op->na != 1);
}

/* The first pass, general: theta_is += p_is s (s = w . (u_j - u_i)) for the states along the bond,
 * gi_s . (u_j - u_i) for the others; theta_js alike. */
static inline void VecStateLoop(const PeriOperator op, const PetscInt bs, const PetscInt ns, const PetscInt na, const PetscScalar *x, PetscScalar *th)
{
  for (PetscInt i = 0; i < op->nloc; i++)
    for (PetscInt b = op->ptr[i]; b < op->ptr[i + 1]; b++) {
      const PetscReal *w = op->w + bs * b, *p = op->p + op->np * b, *g = p + 2 * na;
      const PetscInt   j = op->jl[b];
      PetscScalar      t[PERI_MAX_DOF], tw = 0;
      for (PetscInt d = 0; d < bs; d++) {
        t[d] = x[bs * j + d] - x[bs * i + d];
        tw += w[d] * t[d];
      }
      for (PetscInt s = 0; s < na; s++) {
        th[ns * i + s] += p[2 * s] * tw;
        th[ns * j + s] += p[2 * s + 1] * tw;
      }
      for (PetscInt s = na; s < ns; s++, g += 2 * bs)
        for (PetscInt d = 0; d < bs; d++) {
          th[ns * i + s] += g[d] * t[d];
          th[ns * j + s] += g[bs + d] * t[d];
        }
    }
}

/* The second pass, general: the force along w, s + sum over the states along the bond of
 * p_is q_is + p_js q_js, plus sum over the others of q_is gi_s + q_js gj_s, on j, and its
 * opposite on i. */
static inline void VecSpringStateLoop(const PeriOperator op, const PetscInt bs, const PetscInt ns, const PetscInt na, const PetscScalar *x, const PetscScalar *q, PetscScalar *y)
{
  for (PetscInt i = 0; i < op->nloc; i++)
    for (PetscInt b = op->ptr[i]; b < op->ptr[i + 1]; b++) {
      const PetscReal *w = op->w + bs * b, *p = op->p + op->np * b, *g = p + 2 * na;
      const PetscInt   j = op->jl[b];
      PetscScalar      t = 0, v[PERI_MAX_DOF];
      for (PetscInt d = 0; d < bs; d++) t += w[d] * (x[bs * j + d] - x[bs * i + d]);
      for (PetscInt s = 0; s < na; s++) t += p[2 * s] * q[ns * i + s] + p[2 * s + 1] * q[ns * j + s];
      for (PetscInt d = 0; d < bs; d++) v[d] = t * w[d];
      for (PetscInt s = na; s < ns; s++, g += 2 * bs)
        for (PetscInt d = 0; d < bs; d++) v[d] += q[ns * i + s] * g[d] + q[ns * j + s] * g[bs + d];
      for (PetscInt d = 0; d < bs; d++) {
        y[bs * i + d] -= v[d];
        y[bs * j + d] += v[d];
      }
    }
}

/* The two passes of a family model's product, with the states' ghost exchange between them:
 * every bond is stored once, so an owned state sums the contributions of every rank that holds
 * one of its bonds (reverse), and the ghosts then get their owners' sums (forward). */
static PetscErrorCode StateProduct(const PeriOperator op, const PetscScalar *x, PetscScalar *y)
{
  Vec          tl;
  PetscScalar *th;

  PetscFunctionBeginUser;
  PetscCall(VecGhostGetLocalForm(op->theta, &tl));
  PetscCall(VecSet(tl, 0));
  PetscCall(VecGetArray(tl, &th));
  if (StatesMixed(op) && op->bs == 3 && op->ns == 2 && op->na == 1) /* lps's affine dilatation in 3D: literals, unrolled */
    VecStateLoop(op, 3, 2, 1, x, th);
  else if (StatesMixed(op))
    VecStateLoop(op, op->bs, op->ns, op->na, x, th);
  else if (op->bs == 3)
    StateLoop(op, 3, x, th);
  else
    StateLoop(op, op->bs, x, th);
  PetscCall(VecRestoreArray(tl, &th));
  PetscCall(VecGhostRestoreLocalForm(op->theta, &tl));
  PetscCall(VecGhostUpdateBegin(op->theta, ADD_VALUES, SCATTER_REVERSE));
  PetscCall(VecGhostUpdateEnd(op->theta, ADD_VALUES, SCATTER_REVERSE));
  PetscCall(VecGhostUpdateBegin(op->theta, INSERT_VALUES, SCATTER_FORWARD));
  PetscCall(VecGhostUpdateEnd(op->theta, INSERT_VALUES, SCATTER_FORWARD));
  PetscCall(VecGhostGetLocalForm(op->theta, &tl));
  PetscCall(VecGetArray(tl, &th));
  for (PetscInt i = 0; i < (op->nloc + op->nghost) * op->ns; i++) th[i] *= op->A[i];
  if (StatesMixed(op) && op->bs == 3 && op->ns == 2 && op->na == 1)
    VecSpringStateLoop(op, 3, 2, 1, x, th, y);
  else if (StatesMixed(op))
    VecSpringStateLoop(op, op->bs, op->ns, op->na, x, th, y);
  else if (op->bs == 3)
    SpringStateLoop(op, 3, x, th, y);
  else
    SpringStateLoop(op, op->bs, x, th, y);
  PetscCall(VecRestoreArray(tl, &th));
  PetscCall(VecGhostRestoreLocalForm(op->theta, &tl));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The bond loop of the operator's form; literal block sizes, so that the compiler unrolls. */
static void FormLoop(const PeriOperator op, const PetscScalar *x, PetscScalar *y)
{
  if (op->form == FORM_MICROPOLAR)
    MicropolarLoop(op, x, y);
  else if (op->form == FORM_SHEAR)
    ShearLoop(op, x, y);
  else if (op->form == FORM_SPRING)
    SpringProduct(op, x, y);
  else if (op->bs == 3)
    BondLoop(op, 3, x, y);
  else if (op->bs == 2)
    BondLoop(op, 2, x, y);
  else
    BondLoop(op, op->bs, x, y);
}

/* Flops of one product per bond, for -log_view. */
static PetscReal FormFlops(const PeriOperator op)
{
  return op->form == FORM_MICROPOLAR ? 32 : op->form == FORM_SHEAR ? 14
                                        : op->form == FORM_SPRING  ? 7.0 * op->bs
                                        : op->p && StatesMixed(op) ? (6.0 + 8.0 * (op->ns - op->na)) * op->bs + 4.0 * op->na
                                        : op->p                    ? 10.0 * op->bs + 8
                                                                   : 6.0 * op->bs;
}

/* op->ym = K op->xm (owned part of xm set): ghosts in, the bond loop, ghost contributions back. */
static PetscErrorCode ApplyK(PeriOperator op)
{
  Vec                xl, yl;
  const PetscScalar *xa;
  PetscScalar       *ya;

  PetscFunctionBeginUser;
  PetscCall(PetscLogEventBegin(PERI_EVENT_MatMultFree, 0, 0, 0, 0));
  PetscCall(VecGhostUpdateBegin(op->xm, INSERT_VALUES, SCATTER_FORWARD));
  PetscCall(VecGhostUpdateEnd(op->xm, INSERT_VALUES, SCATTER_FORWARD));
  PetscCall(VecGhostGetLocalForm(op->xm, &xl));
  PetscCall(VecGhostGetLocalForm(op->ym, &yl));
  PetscCall(VecSet(yl, 0));
  PetscCall(VecGetArrayRead(xl, &xa));
  PetscCall(VecGetArray(yl, &ya));
  if (op->p)
    PetscCall(StateProduct(op, xa, ya));
  else
    FormLoop(op, xa, ya);
  PetscCall(VecRestoreArray(yl, &ya));
  PetscCall(VecRestoreArrayRead(xl, &xa));
  PetscCall(VecGhostRestoreLocalForm(op->ym, &yl));
  PetscCall(VecGhostRestoreLocalForm(op->xm, &xl));
  PetscCall(VecGhostUpdateBegin(op->ym, ADD_VALUES, SCATTER_REVERSE));
  PetscCall(VecGhostUpdateEnd(op->ym, ADD_VALUES, SCATTER_REVERSE));
  PetscCall(PetscLogFlops(FormFlops(op) * op->ptr[op->nloc]));
  PetscCall(PetscLogEventEnd(PERI_EVENT_MatMultFree, 0, 0, 0, 0));
  PetscFunctionReturn(PETSC_SUCCESS);
}

static PetscErrorCode ShellMult(Mat A, Vec x, Vec y)
{
  Shell             *sh;
  const PetscScalar *xa;
  PetscScalar       *ma, *ya;

  PetscFunctionBeginUser;
  PetscCall(MatShellGetContext(A, &sh));
  /* scaled before K: K's entries times x may overflow where the scaled ones do not */
  PetscCall(VecAXPBY(sh->op->xm, sh->scale, 0, x));
  PetscCall(VecGetArray(sh->op->xm, &ma));
  for (PetscInt k = 0; k < sh->nheld; k++) ma[sh->held[k]] = 0;
  PetscCall(VecRestoreArray(sh->op->xm, &ma));
  PetscCall(ApplyK(sh->op));
  PetscCall(VecCopy(sh->op->ym, y));
  PetscCall(VecGetArrayRead(x, &xa));
  PetscCall(VecGetArray(y, &ya));
  for (PetscInt k = 0; k < sh->nheld; k++) ya[sh->held[k]] = sh->hd[k] * xa[sh->held[k]];
  PetscCall(VecRestoreArray(y, &ya));
  PetscCall(VecRestoreArrayRead(x, &xa));
  PetscFunctionReturn(PETSC_SUCCESS);
}

static PetscErrorCode ComputeDiagonal(PeriOperator);

static PetscErrorCode ShellGetDiagonal(Mat A, Vec d)
{
  Shell       *sh;
  PetscScalar *da;

  PetscFunctionBeginUser;
  PetscCall(MatShellGetContext(A, &sh));
  if (sh->op->kdiag_stale) PetscCall(ComputeDiagonal(sh->op));
  PetscCall(VecCopy(sh->op->kdiag, d));
  PetscCall(VecScale(d, sh->scale));
  PetscCall(VecGetArray(d, &da));
  for (PetscInt k = 0; k < sh->nheld; k++) da[sh->held[k]] = sh->hd[k];
  PetscCall(VecRestoreArray(d, &da));
  PetscFunctionReturn(PETSC_SUCCESS);
}

static PetscErrorCode ShellScale(Mat A, PetscScalar a)
{
  Shell *sh;

  PetscFunctionBeginUser;
  PetscCall(MatShellGetContext(A, &sh));
  sh->scale *= a;
  for (PetscInt k = 0; k < sh->nheld; k++) sh->hd[k] *= a;
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Appends the owned rows to the held list (sorted, without repeats), their diagonal diag. */
static PetscErrorCode ShellHold(Mat A, Shell *sh, PetscInt n, const PetscInt rows[], PetscScalar diag)
{
  PetscInt   rstart, rend, *held;
  PetscReal *hd;

  PetscFunctionBeginUser;
  PetscCall(MatGetOwnershipRange(A, &rstart, &rend));
  PetscCall(PetscMalloc2(sh->nheld + n, &held, sh->nheld + n, &hd));
  PetscCall(PetscArraycpy(held, sh->held, sh->nheld));
  PetscCall(PetscArraycpy(hd, sh->hd, sh->nheld));
  for (PetscInt k = 0; k < n; k++) {
    PetscCheck(rows[k] >= rstart && rows[k] < rend, PETSC_COMM_SELF, PETSC_ERR_SUP, "the matrix-free operator holds owned rows only (row %" PetscInt_FMT ")", rows[k]);
    held[sh->nheld + k] = rows[k] - rstart;
    hd[sh->nheld + k]   = diag;
  }
  n += sh->nheld;
  PetscCall(PetscSortIntWithScalarArray(n, held, hd));
  sh->nheld = 0;
  for (PetscInt k = 0; k < n; k++) /* a row held twice is held once */
    if (!sh->nheld || held[k] != held[sh->nheld - 1]) {
      held[sh->nheld] = held[k];
      hd[sh->nheld++] = hd[k];
    }
  PetscCall(PetscFree2(sh->held, sh->hd));
  sh->held = held;
  sh->hd   = hd;
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* PETSc's semantics: b -= A(:, rows) x(rows), b(rows) = diag x(rows), then the rows and columns
 * are replaced by diag on the diagonal. */
static PetscErrorCode ShellZeroRowsColumns(Mat A, PetscInt n, const PetscInt rows[], PetscScalar diag, Vec x, Vec b)
{
  Shell *sh;

  PetscFunctionBeginUser;
  PetscCall(MatShellGetContext(A, &sh));
  if (x && b) {
    Vec                z, t;
    PetscScalar       *za, *ba;
    const PetscScalar *xa;
    PetscInt           rstart;
    PetscCall(MatGetOwnershipRange(A, &rstart, NULL));
    PetscCall(VecDuplicate(x, &z));
    PetscCall(VecDuplicate(x, &t));
    PetscCall(VecGetArrayRead(x, &xa));
    PetscCall(VecGetArray(z, &za));
    for (PetscInt k = 0; k < n; k++) za[rows[k] - rstart] = xa[rows[k] - rstart];
    PetscCall(VecRestoreArray(z, &za));
    PetscCall(MatMult(A, z, t));
    PetscCall(VecAXPY(b, -1, t));
    PetscCall(VecGetArray(b, &ba));
    for (PetscInt k = 0; k < n; k++) ba[rows[k] - rstart] = diag * xa[rows[k] - rstart];
    PetscCall(VecRestoreArray(b, &ba));
    PetscCall(VecRestoreArrayRead(x, &xa));
    PetscCall(VecDestroy(&z));
    PetscCall(VecDestroy(&t));
  }
  PetscCall(ShellHold(A, sh, n, rows, diag));
  PetscFunctionReturn(PETSC_SUCCESS);
}

static PetscErrorCode ShellDestroy(void *ctx)
{
  Shell *sh = (Shell *)ctx;

  PetscFunctionBeginUser;
  PetscCall(PetscFree2(sh->held, sh->hd));
  PetscCall(PeriOperatorDestroy(&sh->op));
  PetscCall(PetscFree(sh));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriOperatorMatHeld - the factor a shell of PeriOperatorCreateMat applies K with (MatScale) and its
  held rows (local, sorted: MatZeroRowsColumns). Not collective.
@*/
PetscErrorCode PeriOperatorMatHeld(Mat A, PetscReal *scale, PetscInt *n, const PetscInt **held)
{
  Shell *sh;

  PetscFunctionBeginUser;
  PetscCall(MatShellGetContext(A, &sh));
  *scale = sh->scale;
  *n     = sh->nheld;
  *held  = sh->held;
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriOperatorCreateMat - a MATSHELL applying K from the operator's bond data (which it keeps a
  reference to: it applies the changes PeriOperatorScaleBond makes); MatScale, MatGetDiagonal and MatZeroRowsColumns work on
  it as on an assembled K. Collective.
@*/
PetscErrorCode PeriOperatorCreateMat(PeriSystem sys, Mat *A)
{
  Shell         *sh;
  const PetscInt n = sys->stiffness.op->nloc * sys->stiffness.op->bs;

  PetscFunctionBeginUser;
  PetscCall(PetscNew(&sh));
  sh->op    = sys->stiffness.op;
  sh->scale = 1;
  sys->stiffness.op->refct++;
  PetscCall(MatCreateShell(sys->comm, n, n, PETSC_DETERMINE, PETSC_DETERMINE, sh, A));
  PetscCall(MatShellSetContextDestroy(*A, ShellDestroy));
  PetscCall(MatShellSetManageScalingShifts(*A));
  PetscCall(MatSetBlockSize(*A, sys->stiffness.op->bs));
  PetscCall(MatShellSetOperation(*A, MATOP_MULT, (void (*)(void))ShellMult));
  PetscCall(MatShellSetOperation(*A, MATOP_MULT_TRANSPOSE, (void (*)(void))ShellMult));
  PetscCall(MatShellSetOperation(*A, MATOP_GET_DIAGONAL, (void (*)(void))ShellGetDiagonal));
  PetscCall(MatShellSetOperation(*A, MATOP_SCALE, (void (*)(void))ShellScale));
  PetscCall(MatShellSetOperation(*A, MATOP_ZERO_ROWS_COLUMNS, (void (*)(void))ShellZeroRowsColumns));
  PetscCall(MatSetOption(*A, MAT_SYMMETRIC, PETSC_TRUE));
  PetscCall(MatSetOption(*A, MAT_SYMMETRY_ETERNAL, PETSC_TRUE));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriOperatorWhyNotModel - why the matrix-free operator cannot apply the model's bonds, or NULL
  when their blocks have one of its forms (central force, or a 2D shear or micropolar bond).
  Not collective.
@*/
const char *PeriOperatorWhyNotModel(PeriModel m)
{
  if (m->central_force) return NULL;
  if (!m->ops.bond_stiffness || m->ops.family_stiffness) return "the model has no per-bond blocks";
  if (m->dim == 2 && (m->dofs == 2 || m->dofs == 3)) return NULL;
  return "the model's bonds are neither central springs (pmb, npmb, cpmb) nor 2D shear (pds) or micropolar (mppd, gerstle) bonds";
}

/* The form of the model's blocks and the numbers it stores per bond. */
static void ModelForm(PeriModel m, PeriOperator op)
{
  op->form = m->central_force ? FORM_CENTRAL : m->dofs == 2 ? FORM_SHEAR
                                                            : FORM_MICROPOLAR;
  op->nw   = op->form == FORM_CENTRAL ? m->dofs : op->form == FORM_SHEAR ? 3
                                                                         : 7;
}

/* The numbers w[] of bond block Ke in the operator's form (top of the file); for the central form
 * k is the trace of the first dim x dim block. */
static void FormNumbers(const PeriOperator op, const PeriBondGeometry *g, const PetscReal Ke[], PetscReal w[])
{
  const PetscInt n = 2 * op->bs;
  PetscReal      k = 0;

  if (Central(op)) {
    for (PetscInt a = 0; a < op->bs; a++) k += Ke[a * n + a];
    for (PetscInt d = 0; d < op->bs; d++) w[d] = PetscSqrtReal(PetscMax(k, 0)) * g->xi[d] / g->length;
    return;
  }
  w[0] = Ke[0];
  w[1] = Ke[1];
  w[2] = Ke[n + 1];
  if (op->form == FORM_SHEAR) return;
  w[3] = Ke[2];
  w[4] = Ke[n + 2];
  w[5] = Ke[2 * n + 2];
  w[6] = Ke[2 * n + 5];
}

/* The block that the numbers w[] stand for: what FormNumbers read it from, if it had the form. */
static void FormBlock(const PeriOperator op, const PetscReal w[], PetscReal Ke[])
{
  const PetscInt n = 2 * op->bs, nu = op->form == FORM_MICROPOLAR ? 2 : op->bs;
  PetscReal      A[PERI_MAX_DOF * PERI_MAX_DOF];

  for (PetscInt r = 0; r < nu; r++)
    for (PetscInt c = 0; c < nu; c++) A[r * nu + c] = Central(op) ? w[r] * w[c] : w[r + c];
  for (PetscInt a = 0; a < n * n; a++) Ke[a] = 0;
  for (PetscInt e = 0; e < 2; e++)
    for (PetscInt f = 0; f < 2; f++)
      for (PetscInt r = 0; r < nu; r++)
        for (PetscInt c = 0; c < nu; c++) Ke[(e * op->bs + r) * n + f * op->bs + c] = (e == f ? 1 : -1) * A[r * nu + c];
  if (op->form != FORM_MICROPOLAR) return;
  for (PetscInt e = 0; e < 2; e++)
    for (PetscInt r = 0; r < 2; r++) { /* c couples each end's forces to both rotations, and back */
      const PetscReal sign    = e ? -1 : 1;
      Ke[(3 * e + r) * n + 2] = Ke[(3 * e + r) * n + 5] = sign * w[3 + r];
      Ke[2 * n + 3 * e + r] = Ke[5 * n + 3 * e + r] = sign * w[3 + r];
    }
  Ke[2 * n + 2] = Ke[5 * n + 5] = w[5];
  Ke[2 * n + 5] = Ke[5 * n + 2] = w[6];
}

/* The operator's numbers of bond block Ke, checked: an error when Ke does not have the form. */
static PetscErrorCode BondNumbers(PeriModel m, const PeriOperator op, const PeriBondGeometry *g, const PetscReal Ke[], PetscReal w[])
{
  const PetscInt n = 2 * op->bs;
  PetscReal      Kf[4 * PERI_MAX_DOF * PERI_MAX_DOF], dev = 0, size = 0;

  PetscFunctionBeginUser;
  FormNumbers(op, g, Ke, w);
  FormBlock(op, w, Kf);
  for (PetscInt a = 0; a < n * n; a++) {
    size = PetscMax(size, PetscAbsReal(Ke[a]));
    dev  = PetscMax(dev, PetscAbsReal(Ke[a] - Kf[a]));
  }
  /* moduli beyond double precision: the solve's check of K's diagonal names the units; a block
     of subnormal entries (a bond softened to 1e-300 of itself, as a fuzzed checkpoint gave) has no
     relative precision left to check its form with */
  if (PetscIsInfOrNanReal(size) || (size > 0 && !PetscIsNormalReal(size))) PetscFunctionReturn(PETSC_SUCCESS);
  /* a central spring with k < 0 is rebuilt with k = 0, and fails here too */
  PetscCheck(dev <= 1e-10 * size, PETSC_COMM_SELF, PETSC_ERR_PLIB, "model %s: the block of bond %" PetscInt_FMT "-%" PetscInt_FMT " is not of the %s form (deviation %g of %g): the matrix-free operator cannot apply it", m->type, g->i, g->j,
             Central(op) ? "central-spring (k >= 0)" : op->form == FORM_SHEAR ? "shear"
                                                                              : "micropolar",
             (double)dev, (double)size);
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* p[0..1] = the multiples of w that state s's weights gi, gj (ops.bond_state) are (the central
 * form), an error when they are not parallel to it. */
static PetscErrorCode AlongBond(PeriModel m, const PeriOperator op, const PeriBondGeometry *g, PetscInt s, const PetscReal w[], PetscReal p[])
{
  PetscReal gv[2][PERI_MAX_DOF], ww = 0;

  PetscFunctionBeginUser;
  m->ops.bond_state(m, g, s, gv[0], gv[1]);
  for (PetscInt d = 0; d < op->bs; d++) ww += w[d] * w[d];
  for (PetscInt e = 0; e < 2; e++) {
    PetscReal gw = 0, dev = 0, size = 0;
    for (PetscInt d = 0; d < op->bs; d++) gw += gv[e][d] * w[d];
    p[e] = ww > 0 ? gw / ww : 0;
    for (PetscInt d = 0; d < op->bs; d++) {
      size = PetscMax(size, PetscAbsReal(gv[e][d]));
      dev  = PetscMax(dev, PetscAbsReal(gv[e][d] - p[e] * w[d]));
    }
    PetscCheck(dev <= 1e-10 * size, PETSC_COMM_SELF, PETSC_ERR_PLIB, "model %s: the weights of state %" PetscInt_FMT " of bond %" PetscInt_FMT "-%" PetscInt_FMT " are not along its spring (deviation %g of %g): the matrix-free operator cannot apply them", m->type, s, g->i, g->j, (double)dev, (double)size);
  }
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The bond's np state numbers: the multiples of w for the leading na states, then the others'
 * weights gi, gj as vectors. */
static PetscErrorCode StateNumbers(PeriModel m, const PeriOperator op, const PeriBondGeometry *g, const PetscReal w[], PetscReal p[])
{
  PetscFunctionBeginUser;
  for (PetscInt s = 0; s < op->na; s++) PetscCall(AlongBond(m, op, g, s, w, p + 2 * s));
  for (PetscInt s = op->na, o = 2 * op->na; s < op->ns; s++, o += 2 * op->bs) m->ops.bond_state(m, g, s, p + o, p + o + op->bs);
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Whether stored bond k of particle i is one of the operator's: live, and not a self-image (whose
 * block cancels). */
static inline PetscBool OperatorBond(const PeriBonds *b, PetscInt i, PetscInt k)
{
  return (PetscBool)(b->live[k] && b->j[k] != i);
}

/* Whether the central form can be the spring form: no state terms, and every operator bond's
 * vector is X_j - X_i to the bit (a periodic image's is not; a list without vectors has them so). */
static PetscErrorCode SpringsFromCoordinates(PeriSystem sys, const PeriOperator op, PetscBool *springs)
{
  PetscFunctionBeginUser;
  *springs = PETSC_TRUE;
  /* the product gathers X_j beside u_j: 1.20x the vector form's time on the thin 102,400-site
     plate of tests/perf/dynamic_lammps.sh (its neighbours in z are 25,600 rows apart, beyond the
     caches), 1.1x on a cube, for 16 bytes less a bond (docs/performance.md) */
  PetscCall(PetscOptionsGetBool(NULL, NULL, "-peri_operator_springs", springs, NULL));
  if (op->form != FORM_CENTRAL || sys->model->ops.bond_state) *springs = PETSC_FALSE;
  if (*springs) *springs = PeriSystemBondVectorsFromCoordinates(sys);
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The ghosts the operator's bonds reach, sorted by global index (op->ghost), and each local
 * particle's number in the operator's local numbering (loc: owned ones as they are, ghosts after
 * them; -1 for ghosts without an operator bond). Per particle, not per bond: this runs while the
 * bond list and the operator's arrays are both alive, at the set-up's memory peak. */
static PetscErrorCode NumberGhosts(PeriSystem sys, PeriOperator op, PetscInt loc[])
{
  const PeriDisc  *disc = &sys->disc;
  const PeriBonds *b    = &disc->bonds;
  const PetscInt   n = disc->particles.n, no = disc->nowned;
  PetscInt        *order;

  PetscFunctionBeginUser;
  for (PetscInt q = 0; q < n; q++) loc[q] = q < no ? q : -1;
  for (PetscInt i = b->rstart; i < b->rend; i++)
    for (PetscInt k = b->offset[i - b->rstart]; k < b->offset[i - b->rstart + 1]; k++)
      if (OperatorBond(b, i, k) && b->j[k] >= no) loc[b->j[k]] = 0;
  op->nghost = 0;
  for (PetscInt q = no; q < n; q++) op->nghost += loc[q] == 0;
  PetscCall(PetscMalloc1(op->nghost + 1, &op->ghost));
  PetscCall(PetscMalloc1(op->nghost + 1, &order));
  op->nghost = 0;
  for (PetscInt q = no; q < n; q++)
    if (loc[q] == 0) {
      op->ghost[op->nghost] = disc->particles.global[q];
      order[op->nghost++]   = q;
    }
  PetscCall(PetscSortIntWithArray(op->nghost, op->ghost, order));
  for (PetscInt g = 0; g < op->nghost; g++) loc[order[g]] = op->nloc + g;
  PetscCall(PetscFree(order));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The spring form's coordinates on the operator's local numbering. */
static PetscErrorCode SpringCoordinates(PeriSystem sys, PeriOperator op, const PetscInt loc[])
{
  const PeriParticles *p = &sys->disc.particles;

  PetscFunctionBeginUser;
  PetscCall(PetscCalloc1(2 * (op->nloc + op->nghost) * op->bs, &op->X));
  for (PetscInt q = 0; q < p->n; q++)
    for (PetscInt d = 0; d < op->bs && loc[q] >= 0; d++) op->X[2 * op->bs * loc[q] + d] = p->x[3 * q + d];
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The live bonds of the owned particles as (jl, w) in the local numbering loc (NumberGhosts). */
static PetscErrorCode FillBonds(PeriSystem sys, PeriOperator op, const PetscInt loc[])
{
  const PeriBonds *b = &sys->disc.bonds;
  PeriModel        m = sys->model;
  PetscReal        Ke[4 * PERI_MAX_DOF * PERI_MAX_DOF], w[PERI_MAX_DOF * PERI_MAX_DOF];
  PeriBondGeometry g;
  PetscInt         nb = 0;

  PetscFunctionBeginUser;
  PetscCall(PetscMalloc1(op->nloc + 1, &op->ptr));
  PetscCall(PetscMalloc2(b->nbonds, &op->jl, b->nbonds * op->nw, &op->w));
  if (sys->bond_state.failure.active) PetscCall(PetscMalloc1(b->nbonds, &op->slot));
  if (m->ops.bond_state) {
    op->ns = m->nstates;
    op->na = PetscMin(m->states_along_bonds, m->nstates);
    op->np = 2 * op->na + 2 * (op->ns - op->na) * op->bs;
    PetscCall(PetscMalloc1(op->np * b->nbonds, &op->p));
  }
  for (PetscInt i = b->rstart; i < b->rend; i++) {
    op->ptr[i - b->rstart] = nb;
    for (PetscInt k = b->offset[i - b->rstart]; k < b->offset[i - b->rstart + 1]; k++) {
      if (op->slot) op->slot[k] = -1;
      if (!OperatorBond(b, i, k)) continue;
      if (op->slot) op->slot[k] = nb;
      PetscCall(PeriSystemBondGeometry(sys, i, k, &g));
      m->ops.bond_stiffness(m, &g, Ke);
      PetscCall(BondNumbers(m, op, &g, Ke, w));
      if (op->form == FORM_SPRING) { /* sqrt(k) / |xi| = |w| / |xi| */
        PetscReal ww = 0, xx = 0;
        for (PetscInt d = 0; d < op->bs; d++) {
          ww += w[d] * w[d];
          xx += g.xi[d] * g.xi[d];
        }
        op->w[nb] = PetscSqrtReal(ww / xx);
      } else
        PetscCall(PetscArraycpy(op->w + nb * op->nw, w, op->nw));
      if (op->p) PetscCall(StateNumbers(m, op, &g, op->w + nb * op->nw, op->p + op->np * nb));
      op->jl[nb++] = loc[g.j];
    }
  }
  op->ptr[op->nloc] = nb;
  if (op->form == FORM_SPRING) PetscCall(SpringCoordinates(sys, op, loc));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The live bonds of the owned particles as (jl, w), ghosts numbered after the owned ones; the
 * spring form where it applies (SpringsFromCoordinates). */
static PetscErrorCode CollectBonds(PeriSystem sys, PeriOperator op)
{
  PetscInt      *loc;
  PetscBool      springs;
  PetscErrorCode ierr;

  PetscFunctionBeginUser;
  PetscCall(SpringsFromCoordinates(sys, op, &springs));
  if (springs) {
    op->form = FORM_SPRING;
    op->nw   = 1;
  }
  PetscCall(PetscMalloc1(sys->disc.particles.n, &loc));
  ierr = NumberGhosts(sys, op, loc); /* a bond block of the wrong form is an error: loc is freed first */
  if (!ierr) ierr = FillBonds(sys, op, loc);
  PetscCall(PetscFree(loc));
  PetscCall(ierr);
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The spring form's bond vector xi = X_j - X_i of bond b of owned particle i; its squared length. */
static PetscReal SpringVector(const PeriOperator op, PetscInt i, PetscInt b, PetscReal e[])
{
  PetscReal ee = 0;
  for (PetscInt d = 0; d < op->bs; d++) {
    e[d] = op->X[2 * op->bs * op->jl[b] + d] - op->X[2 * op->bs * i + d];
    ee += e[d] * e[d];
  }
  return ee;
}

/* The diagonal of the block of bond b of owned particle i at either end. */
static void FormDiagonal(const PeriOperator op, PetscInt i, PetscInt b, PetscReal diag[])
{
  const PetscReal *w = op->w + op->nw * b;

  if (op->form == FORM_SPRING) {
    SpringVector(op, i, b, diag);
    for (PetscInt d = 0; d < op->bs; d++) diag[d] = PetscSqr(w[0] * diag[d]);
  } else if (op->form == FORM_CENTRAL)
    for (PetscInt d = 0; d < op->bs; d++) diag[d] = PetscSqr(w[d]);
  else {
    diag[0] = w[0];
    diag[1] = w[2];
    if (op->form == FORM_MICROPOLAR) diag[2] = w[5];
  }
}

/* Ghost exchange of a ghosted vector: the ranks' partial sums to the owner, then back. */
static PetscErrorCode GhostSum(Vec v)
{
  PetscFunctionBeginUser;
  PetscCall(VecGhostUpdateBegin(v, ADD_VALUES, SCATTER_REVERSE));
  PetscCall(VecGhostUpdateEnd(v, ADD_VALUES, SCATTER_REVERSE));
  PetscCall(VecGhostUpdateBegin(v, INSERT_VALUES, SCATTER_FORWARD));
  PetscCall(VecGhostUpdateEnd(v, INSERT_VALUES, SCATTER_FORWARD));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Each particle's own state gradients S_ps = d theta_ps / d u_p = sum of -gi_s (bonds stored at
 * p) and +gj_s (bonds toward p), ns bs per particle in sg's local form, summed over the ranks and
 * copied to the ghosts; with T (theta's local form) also sum_d |g_sd| over p's bonds per state,
 * ||G_ps||_1 without S_ps's own share. Scratch use of sg and theta. Collective. */
static PetscErrorCode StateOwnGradients(PeriOperator op, PetscBool abs_sums)
{
  const PetscInt bs = op->bs, ns = op->ns;
  Vec            sl, tl;
  PetscScalar   *S, *T;

  PetscFunctionBeginUser;
  PetscCall(VecGhostGetLocalForm(op->sg, &sl));
  PetscCall(VecGhostGetLocalForm(op->theta, &tl));
  PetscCall(VecSet(sl, 0));
  PetscCall(VecSet(tl, 0));
  PetscCall(VecGetArray(sl, &S));
  PetscCall(VecGetArray(tl, &T));
  for (PetscInt i = 0; i < op->nloc; i++)
    for (PetscInt b = op->ptr[i]; b < op->ptr[i + 1]; b++) {
      const PetscInt j = op->jl[b];
      for (PetscInt s = 0; s < ns; s++)
        for (PetscInt d = 0; d < bs; d++) {
          const PetscReal gi = StateWeight(op, b, s, 0, d), gj = StateWeight(op, b, s, 1, d);
          S[(ns * i + s) * bs + d] -= gi;
          S[(ns * j + s) * bs + d] += gj;
          T[ns * i + s] += PetscAbsReal(gi);
          T[ns * j + s] += PetscAbsReal(gj);
        }
    }
  PetscCall(VecRestoreArray(tl, &T));
  PetscCall(VecRestoreArray(sl, &S));
  PetscCall(VecGhostRestoreLocalForm(op->theta, &tl));
  PetscCall(VecGhostRestoreLocalForm(op->sg, &sl));
  PetscCall(GhostSum(op->sg));
  if (abs_sums) PetscCall(GhostSum(op->theta));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The state terms' diagonal, added to ya (the local form of ym): sum_q,s A_qs (d theta_qs / d u_p)^2:
 * a bond (i, j) adds gi_s to theta_is's gradient at j and gj_s to theta_js's at i; a particle's
 * own gradients are S_ps (StateOwnGradients). Collective. */
static PetscErrorCode StateDiagonal(PeriOperator op, PetscScalar *ya)
{
  const PetscInt bs = op->bs, ns = op->ns;
  PetscScalar   *S;

  PetscFunctionBeginUser;
  PetscCall(StateOwnGradients(op, PETSC_FALSE));
  PetscCall(VecGetArray(op->sg, &S));
  for (PetscInt i = 0; i < op->nloc; i++)
    for (PetscInt s = 0; s < ns; s++) {
      for (PetscInt d = 0; d < bs; d++) ya[bs * i + d] += op->A[ns * i + s] * PetscSqr(S[(ns * i + s) * bs + d]);
      for (PetscInt b = op->ptr[i]; b < op->ptr[i + 1]; b++)
        for (PetscInt d = 0; d < bs; d++) {
          ya[bs * op->jl[b] + d] += op->A[ns * i + s] * PetscSqr(StateWeight(op, b, s, 0, d));
          ya[bs * i + d] += op->A[ns * op->jl[b] + s] * PetscSqr(StateWeight(op, b, s, 1, d));
        }
    }
  PetscCall(VecRestoreArray(op->sg, &S));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* op->kdiag: the diagonal of K, the sum over the bonds at each end of their blocks' diagonals.
 * Collective. */
static PetscErrorCode ComputeDiagonal(PeriOperator op)
{
  Vec          yl;
  PetscScalar *ya;

  PetscFunctionBeginUser;
  PetscCall(VecGhostGetLocalForm(op->ym, &yl));
  PetscCall(VecSet(yl, 0));
  PetscCall(VecGetArray(yl, &ya));
  for (PetscInt i = 0; i < op->nloc; i++)
    for (PetscInt b = op->ptr[i]; b < op->ptr[i + 1]; b++) {
      PetscReal diag[PERI_MAX_DOF];
      FormDiagonal(op, i, b, diag);
      for (PetscInt d = 0; d < op->bs; d++) {
        ya[op->bs * i + d] += diag[d];
        ya[op->bs * op->jl[b] + d] += diag[d];
      }
    }
  if (op->p) PetscCall(StateDiagonal(op, ya));
  PetscCall(VecRestoreArray(yl, &ya));
  PetscCall(VecGhostRestoreLocalForm(op->ym, &yl));
  PetscCall(VecGhostUpdateBegin(op->ym, ADD_VALUES, SCATTER_REVERSE));
  PetscCall(VecGhostUpdateEnd(op->ym, ADD_VALUES, SCATTER_REVERSE));
  PetscCall(VecCopy(op->ym, op->kdiag));
  op->kdiag_stale = PETSC_FALSE;
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The state terms' ghosted states (ns per particle), their scratch sg and their moduli A on the
 * operator's local numbering (the ghosts' from their owners). */
static PetscErrorCode SetUpStates(PeriSystem sys, PeriOperator op)
{
  const PetscInt     ns = op->ns;
  Vec                al;
  const PetscScalar *a;
  PetscScalar       *w;

  PetscFunctionBeginUser;
  PetscCall(VecCreateGhostBlock(sys->comm, ns, op->nloc * ns, PETSC_DECIDE, op->nghost, op->ghost, &op->theta));
  PetscCall(VecCreateGhostBlock(sys->comm, ns * op->bs, op->nloc * ns * op->bs, PETSC_DECIDE, op->nghost, op->ghost, &op->sg));
  PetscCall(VecGetArrayWrite(op->theta, &w));
  for (PetscInt i = 0; i < op->nloc; i++)
    for (PetscInt s = 0; s < ns; s++) w[ns * i + s] = sys->model->ops.state_modulus(sys->model, i, s);
  PetscCall(VecRestoreArrayWrite(op->theta, &w));
  PetscCall(VecGhostUpdateBegin(op->theta, INSERT_VALUES, SCATTER_FORWARD));
  PetscCall(VecGhostUpdateEnd(op->theta, INSERT_VALUES, SCATTER_FORWARD));
  PetscCall(PetscMalloc1((op->nloc + op->nghost) * ns, &op->A));
  PetscCall(VecGhostGetLocalForm(op->theta, &al));
  PetscCall(VecGetArrayRead(al, &a));
  for (PetscInt i = 0; i < (op->nloc + op->nghost) * ns; i++) op->A[i] = PetscRealPart(a[i]);
  PetscCall(VecRestoreArrayRead(al, &a));
  PetscCall(VecGhostRestoreLocalForm(op->theta, &al));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The ghosted work vectors and the diagonal. */
static PetscErrorCode SetUpGhosts(PeriSystem sys, PeriOperator op)
{
  PetscFunctionBeginUser;
  PetscCall(VecCreateGhostBlock(sys->comm, op->bs, op->nloc * op->bs, PETSC_DECIDE, op->nghost, op->ghost, &op->xm));
  PetscCall(VecDuplicate(op->xm, &op->ym));
  if (op->p) PetscCall(SetUpStates(sys, op));
  PetscCall(PeriSystemCreateVec(sys, &op->kdiag));
  PetscCall(ComputeDiagonal(op));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Adds to each owned particle's full the state terms' energy of the uniform expansion u = X on
 * the springs' scale (where a spring's k |xi|^2 is twice its energy at each end): 2 sum_s A_is
 * theta_is^2, so that the scaled short-range springs store the whole K's energy of it. Collective. */
static PetscErrorCode AddStateExpansion(PeriSystem sys, PeriOperator op, PetscReal full[])
{
  const PeriDisc  *disc = &sys->disc;
  const PeriBonds *b    = &disc->bonds;
  const PetscInt   ns   = op->ns;
  PetscReal       *theta;
  PetscInt         t = 0;

  PetscFunctionBeginUser;
  PetscCall(PetscCalloc1(disc->particles.n * ns, &theta));
  for (PetscInt i = b->rstart; i < b->rend; i++)
    for (PetscInt k = b->offset[i - b->rstart]; k < b->offset[i - b->rstart + 1]; k++) {
      if (!OperatorBond(b, i, k)) continue;
      for (PetscInt s = 0; s < ns; s++)
        for (PetscInt d = 0; d < op->bs; d++) {
          theta[ns * i + s] += StateWeight(op, t, s, 0, d) * b->xi[3 * k + d];
          theta[ns * b->j[k] + s] += StateWeight(op, t, s, 1, d) * b->xi[3 * k + d];
        }
      t++;
    }
  PetscCall(PeriDiscGhostsToOwners(disc, MPIU_REAL, ns, MPI_SUM, theta));
  for (PetscInt i = 0; i < disc->nowned; i++) {
    for (PetscInt s = 0; s < ns; s++) full[i] += 2 * sys->model->ops.state_modulus(sys->model, i, s) * PetscSqr(theta[ns * i + s]);
    full[i] = PetscMax(full[i], 0);
  }
  PetscCall(PetscFree(theta));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Per particle of the local view, sum of k |xi|^2 over its bonds (full) and over those of the short
 * range (part): the energies a uniform expansion stores in them, up to a common factor (with k the
 * trace of the translational block for the shear and micropolar forms). Collective. */
static PetscErrorCode ExpansionEnergies(PeriSystem sys, PeriOperator op, PetscReal full[], PetscReal part[])
{
  const PeriDisc  *disc = &sys->disc;
  const PeriBonds *b    = &disc->bonds;
  PetscInt         t    = 0; /* the operator's bond: CollectBonds keeps the OperatorBond ones in order */

  PetscFunctionBeginUser;
  PetscCall(PetscArrayzero(full, disc->particles.n));
  PetscCall(PetscArrayzero(part, disc->particles.n));
  for (PetscInt i = b->rstart; i < b->rend; i++)
    for (PetscInt k = b->offset[i - b->rstart]; k < b->offset[i - b->rstart + 1]; k++) {
      PetscReal e = 0, diag[PERI_MAX_DOF];
      if (!OperatorBond(b, i, k)) continue;
      /* the trace of the translational block times |xi|^2: k |xi|^2 for a central spring */
      FormDiagonal(op, i - b->rstart, t++, diag);
      for (PetscInt d = 0; d < (op->form == FORM_MICROPOLAR ? 2 : op->bs); d++) e += diag[d] * PetscSqr(PeriDiscBondLength(disc, i, k));
      full[i] += e;
      full[b->j[k]] += e;
      if (!PeriShortRangeHolds(&op->short_range, disc, i, k)) continue;
      part[i] += e;
      part[b->j[k]] += e;
    }
  PetscCall(PeriDiscGhostsToOwners(disc, MPIU_REAL, 1, MPI_SUM, full));
  PetscCall(PeriDiscGhostsToOwners(disc, MPIU_REAL, 1, MPI_SUM, part));
  if (op->p) PetscCall(AddStateExpansion(sys, op, full));
  PetscCall(PeriDiscOwnersToGhosts(disc, MPIU_REAL, 1, full));
  PetscCall(PeriDiscOwnersToGhosts(disc, MPIU_REAL, 1, part));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The SHORTEST shortest bond lengths of each particle, ascending (PETSC_MAX_REAL where it has
 * fewer): a particle's reach in the preconditioning matrix is radius times the last, its
 * 2 dim-th shortest. On a grid the 2 dim shortest are its nearest neighbours, all as long as the
 * shortest; on a stochastic mesh split into slivers a particle's one shortest bond may be a
 * fraction of the others, and a reach from it kept a single bond direction: GAMG met a
 * preconditioning matrix without full rank (DIVERGED_INDEFINITE_PC) on the split bars of
 * docs/mesh.md. */
#define SHORTEST 6

static void ShortestInsert(PetscReal s[], PetscInt m, PetscReal len)
{
  PetscInt a = m - 1;
  if (len >= s[a]) return;
  for (; a > 0 && s[a - 1] > len; a--) s[a] = s[a - 1];
  s[a] = len;
}

/* MPI reduction of ShortestInsert arrays (m = the unit's length in reals): the m smallest of both. */
static void MPIAPI ShortestMerge(void *in, void *inout, int *len, MPI_Datatype *type)
{
  int        size;
  PetscReal *a = (PetscReal *)in, *b = (PetscReal *)inout;
  PetscInt   m;

  (void)MPI_Type_size(*type, &size);
  m = size / (int)sizeof(PetscReal);
  for (int u = 0; u < *len; u++, a += m, b += m)
    for (PetscInt q = 0; q < m; q++) ShortestInsert(b, m, a[q]);
}

/* Each local particle's m shortest operator bonds, over every rank's (ghosts' from their owners). */
static PetscErrorCode ShortestBonds(const PeriDisc *disc, PetscInt m, PetscReal s[])
{
  const PeriBonds *b = &disc->bonds;
  MPI_Op           merge;

  PetscFunctionBeginUser;
  for (PetscInt q = 0; q < m * disc->particles.n; q++) s[q] = PETSC_MAX_REAL;
  for (PetscInt i = b->rstart; i < b->rend; i++)
    for (PetscInt k = b->offset[i - b->rstart]; k < b->offset[i - b->rstart + 1]; k++) {
      if (!OperatorBond(b, i, k)) continue;
      const PetscReal len = PeriDiscBondLength(disc, i, k);
      ShortestInsert(&s[m * i], m, len);
      ShortestInsert(&s[m * b->j[k]], m, len);
    }
  PetscCallMPI(MPI_Op_create(ShortestMerge, 1, &merge));
  PetscCall(PeriDiscGhostsToOwners(disc, MPIU_REAL, m, merge, s));
  PetscCallMPI(MPI_Op_free(&merge));
  PetscCall(PeriDiscOwnersToGhosts(disc, MPIU_REAL, m, s));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The preconditioning matrix's bonds and scales (PeriShortRange) from the operator's bonds: each
 * particle's reach is radius times its 2 dim-th shortest bond (ShortestBonds), and its scale what
 * its family stores under a uniform expansion (sum of k |xi|^2 over its bonds) over what its short
 * bonds store. A reach from the whole body's shortest bond instead left the coarse particles of a
 * graded mesh without any bond, and the matrix singular. Collective. */
static PetscErrorCode ChooseShortRange(PeriSystem sys, PeriOperator op, PetscReal radius)
{
  const PeriDisc *disc = &sys->disc;
  const PetscInt  n = disc->particles.n, m = PetscMin(2 * disc->particles.dim, SHORTEST);
  PeriShortRange *sr = &op->short_range;
  PetscReal      *full, *part, *s;

  PetscFunctionBeginUser;
  PetscCall(PetscMalloc2(n, &sr->reach, n, &sr->scale));
  PetscCall(PetscMalloc3(n, &full, n, &part, m * n, &s));
  PetscCall(ShortestBonds(disc, m, s));
  /* fewer than m bonds: the longest it has (none: PETSC_MAX_REAL, any bond of a partner's reach) */
  for (PetscInt i = 0; i < n; i++) {
    PetscInt last = m - 1;
    while (last > 0 && s[m * i + last] == PETSC_MAX_REAL) last--;
    sr->reach[i] = s[m * i + last] == PETSC_MAX_REAL ? PETSC_MAX_REAL : s[m * i + last] * radius * (1 + 1e-10);
  }
  PetscCall(ExpansionEnergies(sys, op, full, part));
  /* a particle without bonds has no row to precondition: any scale */
  for (PetscInt i = 0; i < n; i++) sr->scale[i] = part[i] > 0 ? full[i] / part[i] : 1;
  PetscCall(PetscFree3(full, part, s));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The PCs a matrix-free K serves: those that need no entries (Jacobi from its diagonal, none) and
 * GAMG (on the preconditioning matrix). solver.operator: auto takes matrix_free for them only. */
PetscBool PeriOperatorServesPC(const char pc[])
{
  return (PetscBool)(!strcmp(pc, PCGAMG) || PeriOperatorPCWithoutMatrix(pc));
}

/* Whether the PC works from the matrix-free K alone, without a preconditioning matrix: Jacobi,
 * none, and the geometric multigrid (src/system/multigrid.c), whose levels are matrix-free too. */
PetscBool PeriOperatorPCWithoutMatrix(const char pc[])
{
  return (PetscBool)(!strcmp(pc, PCJACOBI) || !strcmp(pc, PCNONE) || !strcmp(pc, PCMG));
}

/*@C
  PeriOperatorCreate - the matrix-free operator of a bond-based model from the live bonds (central
  force, or 2D shear or micropolar: PeriOperatorWhyNotModel),
  and the choice of its preconditioning matrix's bonds (those within radius nearest-neighbour
  distances; PeriOperatorPreconditioner assembles it). Collective.
@*/
PetscErrorCode PeriOperatorCreate(PeriSystem sys, PetscReal radius, PeriOperator *op)
{
  PetscFunctionBeginUser;
  PetscCall(PetscNew(op));
  (*op)->refct = 1;
  (*op)->bs    = sys->model->dofs;
  (*op)->nloc  = sys->disc.bonds.rend - sys->disc.bonds.rstart;
  ModelForm(sys->model, *op);
  PetscCall(CollectBonds(sys, *op));
  PetscCall(SetUpGhosts(sys, *op));
  PetscCall(ChooseShortRange(sys, *op, radius));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The shear and micropolar forms: P <- V P V with V = diag(sqrt(K_rr / P_rr)), so that P's diagonal
 * is K's. The per-particle scale of the short range comes from the energy of a uniform expansion,
 * which the normal springs (spread over the whole horizon) carry; the shear and rotational springs
 * of gerstle weigh 1/|xi|^2 and 1/|xi| and sit mostly in the short bonds, so that scale
 * overstated them (the 57,600-particle gerstle lamina: 48 CG iterations, with this 38). Broken
 * bonds would have to change P as scaled: matrix_free is refused for these forms with failure
 * (PeriMatrixFreeWhyNot). Collective. */
static PetscErrorCode MatchDiagonal(PeriOperator op, Mat P)
{
  Vec                pd;
  const PetscScalar *ka, *pa;
  PetscScalar       *va;

  PetscFunctionBeginUser;
  if (op->kdiag_stale) PetscCall(ComputeDiagonal(op));
  PetscCall(VecDuplicate(op->kdiag, &pd));
  PetscCall(MatGetDiagonal(P, pd));
  PetscCall(VecGetArrayRead(op->kdiag, &ka));
  PetscCall(VecGetArrayRead(pd, &pa));
  PetscCall(VecGetArrayWrite(op->xm, &va));
  /* a DOF without bonds keeps its row */
  for (PetscInt r = 0; r < op->nloc * op->bs; r++) va[r] = PetscRealPart(pa[r]) > 0 && PetscRealPart(ka[r]) > 0 ? PetscSqrtReal(PetscRealPart(ka[r]) / PetscRealPart(pa[r])) : 1;
  PetscCall(VecRestoreArrayWrite(op->xm, &va));
  PetscCall(VecRestoreArrayRead(pd, &pa));
  PetscCall(VecRestoreArrayRead(op->kdiag, &ka));
  PetscCall(VecDestroy(&pd));
  PetscCall(MatDiagonalScale(P, op->xm, op->xm));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriOperatorPreconditioner - sys->stiffness.Kpc, the preconditioning matrix of the matrix-free K, assembled
  on first use: the short bonds' blocks (k e e^T = w w^T, the assembly's own), restricted and
  scaled, broken ones with PERI_BROKEN_SHARE of theirs. Collective.
@*/
PetscErrorCode PeriOperatorPreconditioner(PeriSystem sys)
{
  PetscFunctionBeginUser;
  if (sys->stiffness.Kpc) PetscFunctionReturn(PETSC_SUCCESS);
  PetscCall(PetscLogEventBegin(PERI_EVENT_Assembly, 0, 0, 0, 0));
  PetscCall(PeriAssembleShortRange(sys, &sys->stiffness.op->short_range, PERI_BROKEN_SHARE, &sys->stiffness.Kpc));
  if (!Central(sys->stiffness.op)) PetscCall(MatchDiagonal(sys->stiffness.op, sys->stiffness.Kpc));
  PetscCall(PetscLogEventEnd(PERI_EVENT_Assembly, 0, 0, 0, 0));
  if (!sys->run.log.pc_matrix_counted) { /* summary.json's matrix_mb counts it with the operator */
    PetscReal mb;
    sys->run.log.pc_matrix_counted = PETSC_TRUE;
    PetscCall(PeriMatrixMB(sys->stiffness.Kpc, &mb));
    sys->run.log.matrix_mb += mb;
  }
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The state terms' share of the absolute row sums of K, from above: sum_q,s |A_qs| |G_qs,r|
 * ||G_qs||_1 with G_qs the gradient of theta_qs (StateDiagonal). Adds to ya (ym's local form,
 * reduced by the caller). Uses sg and theta as scratch. Collective. */
static PetscErrorCode StateRowSums(PeriOperator op, PetscScalar *ya)
{
  const PetscInt bs = op->bs, ns = op->ns;
  Vec            sl, tl;
  PetscScalar   *S, *T;

  PetscFunctionBeginUser;
  PetscCall(StateOwnGradients(op, PETSC_TRUE));
  PetscCall(VecGhostGetLocalForm(op->sg, &sl));
  PetscCall(VecGhostGetLocalForm(op->theta, &tl));
  PetscCall(VecGetArray(sl, &S));
  PetscCall(VecGetArray(tl, &T));
  for (PetscInt q = 0; q < (op->nloc + op->nghost) * ns; q++) { /* T becomes |A| ||G||_1 */
    for (PetscInt d = 0; d < bs; d++) T[q] += PetscAbsScalar(S[bs * q + d]);
    T[q] *= PetscAbsReal(op->A[q]);
  }
  for (PetscInt i = 0; i < op->nloc; i++)
    for (PetscInt s = 0; s < ns; s++) {
      for (PetscInt d = 0; d < bs; d++) ya[bs * i + d] += T[ns * i + s] * PetscAbsScalar(S[(ns * i + s) * bs + d]);
      for (PetscInt b = op->ptr[i]; b < op->ptr[i + 1]; b++)
        for (PetscInt d = 0; d < bs; d++) {
          ya[bs * op->jl[b] + d] += T[ns * i + s] * PetscAbsReal(StateWeight(op, b, s, 0, d));
          ya[bs * i + d] += T[ns * op->jl[b] + s] * PetscAbsReal(StateWeight(op, b, s, 1, d));
        }
    }
  PetscCall(VecRestoreArray(tl, &T));
  PetscCall(VecRestoreArray(sl, &S));
  PetscCall(VecGhostRestoreLocalForm(op->theta, &tl));
  PetscCall(VecGhostRestoreLocalForm(op->sg, &sl));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriOperatorRowSums - the absolute row sums of a matrix-free K from above, for Gershgorin's bound:
  the bonds' blocks (PeriStiffnessRowSums) and the state term's. Collective.
@*/
PetscErrorCode PeriOperatorRowSums(PeriSystem sys, Vec sums)
{
  PeriOperator op = sys->stiffness.op;
  Vec          yl;
  PetscScalar *ya;

  PetscFunctionBeginUser;
  PetscCall(PeriStiffnessRowSums(sys, sums));
  if (!op->p) PetscFunctionReturn(PETSC_SUCCESS);
  PetscCall(VecGhostGetLocalForm(op->ym, &yl));
  PetscCall(VecSet(yl, 0));
  PetscCall(VecGetArray(yl, &ya));
  PetscCall(StateRowSums(op, ya));
  PetscCall(VecRestoreArray(yl, &ya));
  PetscCall(VecGhostRestoreLocalForm(op->ym, &yl));
  PetscCall(VecGhostUpdateBegin(op->ym, ADD_VALUES, SCATTER_REVERSE));
  PetscCall(VecGhostUpdateEnd(op->ym, ADD_VALUES, SCATTER_REVERSE));
  PetscCall(VecAXPY(sums, 1, op->ym));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The bytes the operator holds, all ranks. */
PetscErrorCode PeriOperatorMemoryMB(PeriSystem sys, PeriOperator op, PetscReal *mb)
{
  PetscFunctionBeginUser;
  *mb = (op->ptr[op->nloc] * (sizeof(PetscInt) + op->nw * sizeof(PetscReal)) + (op->nloc + 1 + op->nghost) * sizeof(PetscInt) + ((2 * op->nghost + 2 * op->nloc) * op->bs + (op->X ? 2 * (op->nloc + op->nghost) * op->bs : 0)) * sizeof(PetscScalar)) / 1048576.0;
  PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, mb, 1, MPIU_REAL, MPI_SUM, sys->comm));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriOperatorScaleBond - bond k of owned particle i keeps factor times its stiffness: w scales by
  sqrt(factor) (central form), the block's numbers by factor (the others). In the preconditioning matrix a broken bond keeps PERI_BROKEN_SHARE of its block
  (Ke, the block before the change), so that P stays positive definite where K was at the start
  (without them a particle could lose every short bond and keep longer ones) while its cracks
  are nearly K's; softening leaves P as it is. Not collective; PeriOperatorScaled follows the last.
@*/
PetscErrorCode PeriOperatorScaleBond(PeriSystem sys, PetscInt i, PetscInt k, PetscReal factor, const PetscReal Ke[])
{
  PeriOperator   op = sys->stiffness.op;
  const PetscInt t = op->slot ? op->slot[k] : -1, n = 2 * op->bs;
  PetscInt       idx[2] = {sys->disc.particles.global[i], sys->disc.particles.global[sys->disc.bonds.j[k]]};
  PetscReal      dP[4 * PERI_MAX_DOF * PERI_MAX_DOF];

  PetscFunctionBeginUser;
  PetscCheck(t >= 0, PETSC_COMM_SELF, PETSC_ERR_PLIB, "bond %" PetscInt_FMT " of particle %" PetscInt_FMT " has no place in the matrix-free operator", k, i);
  for (PetscInt d = 0; d < op->nw; d++) op->w[op->nw * t + d] *= Central(op) ? PetscSqrtReal(factor) : factor;
  for (PetscInt d = 2 * op->na; op->p && d < op->np; d++) op->p[op->np * t + d] *= PetscSqrtReal(factor); /* the vectors, as the multiples of w do with it */
  if (!sys->stiffness.Kpc || factor > 0 || !PeriShortRangeHolds(&op->short_range, &sys->disc, i, k)) PetscFunctionReturn(PETSC_SUCCESS);
  PetscCheck(Central(op), PETSC_COMM_SELF, PETSC_ERR_PLIB, "the preconditioning matrix of shear and micropolar bonds is diagonally scaled and cannot follow a broken bond");
  for (PetscInt a = 0; a < n * n; a++) dP[a] = -(1 - PERI_BROKEN_SHARE) * PeriShortRangeFactor(&op->short_range, &sys->disc, i, k) * Ke[a];
  PetscCall(MatSetValuesBlocked(sys->stiffness.Kpc, 2, idx, 2, idx, dP, ADD_VALUES));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* After the last PeriOperatorScaleBond: P assembled, the diagonal of K recomputed. Collective. */
PetscErrorCode PeriOperatorScaled(PeriSystem sys)
{
  PetscFunctionBeginUser;
  if (sys->stiffness.Kpc) {
    PetscCall(MatAssemblyBegin(sys->stiffness.Kpc, MAT_FINAL_ASSEMBLY));
    PetscCall(MatAssemblyEnd(sys->stiffness.Kpc, MAT_FINAL_ASSEMBLY));
  }
  sys->stiffness.op->kdiag_stale = PETSC_TRUE;
  PetscFunctionReturn(PETSC_SUCCESS);
}

PetscErrorCode PeriOperatorDestroy(PeriOperator *op)
{
  PetscFunctionBeginUser;
  if (!*op) PetscFunctionReturn(PETSC_SUCCESS);
  if (--(*op)->refct > 0) {
    *op = NULL;
    PetscFunctionReturn(PETSC_SUCCESS);
  }
  PetscCall(PetscFree((*op)->ptr));
  PetscCall(PetscFree2((*op)->jl, (*op)->w));
  PetscCall(PetscFree((*op)->X));
  PetscCall(PetscFree2((*op)->short_range.reach, (*op)->short_range.scale));
  PetscCall(PetscFree((*op)->ghost));
  PetscCall(PetscFree((*op)->slot));
  PetscCall(PetscFree((*op)->p));
  PetscCall(PetscFree((*op)->A));
  PetscCall(VecDestroy(&(*op)->theta));
  PetscCall(VecDestroy(&(*op)->sg));
  PetscCall(VecDestroy(&(*op)->xm));
  PetscCall(VecDestroy(&(*op)->ym));
  PetscCall(VecDestroy(&(*op)->kdiag));
  PetscCall(PetscFree(*op));
  PetscFunctionReturn(PETSC_SUCCESS);
}
