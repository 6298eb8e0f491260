/* Modal analysis: natural frequencies and mode shapes from K x = omega^2 M x (SLEPc, EPS_GHEP),
 * shift-and-invert around a target with a direct factorization, on the free DOFs only (prescribed
 * DOFs are removed, so they give no spurious eigenvalues). M is lumped: rho V_i per translation,
 * rho V_i (dx^2 + dy^2)/12 per rotation (Diana & Casolo sec. 3.1, with r_i^2 for their r_i). */
#include "perilin.h"
#include <slepceps.h>

/* The density of each owned particle: material.rho, or material.rho_by_region {region: rho}
 * (later regions win where they overlap). */
static PetscErrorCode Densities(PeriProblem p, PetscReal **rho)
{
  PeriScene      s    = p->scene;
  const PetscInt nloc = p->bonds.rend - p->bonds.rstart;
  PeriNode       mat, map;

  PetscFunctionBeginUser;
  PetscCall(PetscMalloc1(nloc, rho));
  for (PetscInt i = 0; i < nloc; i++) (*rho)[i] = p->model->material.rho;
  PetscCall(PeriSceneGetNode(s->root, "material", &mat));
  PetscCall(PeriSceneGetMap(s, mat, "rho_by_region", PETSC_FALSE, &map));
  for (PetscInt k = 0; map && k < map->n; k++) {
    PeriRegion *r;
    PetscReal   v;
    PetscCall(PeriRegionFind(s, map->child[k], NULL, p->nregions, p->regions, &r));
    PetscCall(PeriSceneGetReal(s, map, map->child[k]->key, PETSC_TRUE, &v, NULL));
    PeriInputCheck(v > 0, s, map, map->child[k]->key, "must be positive");
    for (PetscInt i = 0; i < nloc; i++)
      if (PeriRegionContains(r, &p->particles.x[3 * (p->bonds.rstart + i)])) (*rho)[i] = v;
  }
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriAssembleMass - the lumped mass matrix, diagonal, in the layout of K. Collective.
@*/
PetscErrorCode PeriAssembleMass(PeriProblem p, Mat *M)
{
  const PetscInt bs = p->model->dofs, nloc = p->bonds.rend - p->bonds.rstart;
  PetscReal     *rho;
  Vec            d;
  PetscScalar   *a;

  PetscFunctionBeginUser;
  PetscCall(MatCreate(p->comm, M));
  PetscCall(MatSetSizes(*M, nloc * bs, nloc * bs, PETSC_DETERMINE, PETSC_DETERMINE));
  PetscCall(MatSetBlockSize(*M, bs));
  PetscCall(MatSetType(*M, MATAIJ));
  PetscCall(MatXAIJSetPreallocation(*M, 1, NULL, NULL, NULL, NULL));
  PetscCall(MatSeqAIJSetPreallocation(*M, 1, NULL));
  PetscCall(MatMPIAIJSetPreallocation(*M, 1, NULL, 0, NULL));
  PetscCall(PeriProblemCreateVec(p, &d));
  PetscCall(Densities(p, &rho));
  PetscCall(VecGetArray(d, &a));
  for (PetscInt i = 0; i < nloc; i++) {
    PetscReal V = p->particles.volume[p->bonds.rstart + i], h = p->particles.spacing[p->bonds.rstart + i];
    for (PetscInt c = 0; c < bs; c++) a[i * bs + c] = p->model->rotational[c] ? rho[i] * V * (h * h + h * h) / 12 : rho[i] * V;
  }
  PetscCall(VecRestoreArray(d, &a));
  PetscCall(PetscFree(rho));
  PetscCall(MatDiagonalSet(*M, d, INSERT_VALUES));
  PetscCall(MatAssemblyBegin(*M, MAT_FINAL_ASSEMBLY));
  PetscCall(MatAssemblyEnd(*M, MAT_FINAL_ASSEMBLY));
  PetscCall(VecDestroy(&d));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The structure's main axis: away from its constraints (a cantilever's length), or, for a free
 * body, its longest extent. Components held at 0 because they are inactive do not count. */
static PetscErrorCode MainAxis(PeriProblem p, PetscInt *axis)
{
  const PeriParticles *pt   = &p->particles;
  PetscReal            s[4] = {0, 0, 0, 0}, best = -1;

  PetscFunctionBeginUser;
  for (PetscInt k = 0; k < p->nconstrained; k++) {
    PetscInt i = p->constrained[k] / p->model->dofs;
    if (p->model->inactive[p->constrained[k] % p->model->dofs]) continue;
    for (PetscInt d = 0; d < pt->dim; d++) s[d] += pt->x[3 * i + d] - 0.5 * (pt->lower[d] + pt->upper[d]);
    s[3] += 1;
  }
  PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, s, 4, MPIU_REAL, MPI_SUM, p->comm));
  *axis = 0;
  for (PetscInt d = 0; d < pt->dim; d++) {
    PetscReal v = s[3] > 0 ? PetscAbsReal(s[d] / s[3]) / (pt->upper[d] - pt->lower[d]) : pt->upper[d] - pt->lower[d];
    if (v > best) {
      best  = v;
      *axis = d;
    }
  }
  PetscFunctionReturn(PETSC_SUCCESS);
}

static PetscErrorCode ReadSettings(PeriProblem p, PetscInt *nev, PetscReal *target_hz)
{
  PeriScene s = p->scene;
  PeriNode  a, mat;

  PetscFunctionBeginUser;
  PetscCall(PeriSceneGetNode(s->root, "analysis", &a));
  *nev       = 6;
  *target_hz = 0;
  PetscCall(PeriSceneGetInt(s, a, "nev", PETSC_FALSE, nev, NULL));
  PetscCall(PeriSceneGetReal(s, a, "target_hz", PETSC_FALSE, target_hz, NULL));
  PeriInputCheck(*nev >= 1, s, a, "nev", "must be at least 1");
  PeriInputCheck(*target_hz >= 0, s, a, "target_hz", "must not be negative");
  PetscCall(PeriSceneGetNode(s->root, "material", &mat));
  PeriInputCheck(p->model->material.rho > 0, s, mat, "rho", "a modal analysis needs the density (material.rho > 0)");
  PeriInputCheck(!p->layers.nfaces, s, s->root, "boundary_layers", "the fictitious layers carry static conditions; a modal analysis takes bc only");
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The owned DOFs that are not prescribed. */
static PetscErrorCode FreeDOFs(PeriProblem p, IS *is)
{
  const PetscInt bs = p->model->dofs, nloc = (p->bonds.rend - p->bonds.rstart) * bs, r0 = p->bonds.rstart * bs;
  PetscInt      *idx, n = 0, c = 0;

  PetscFunctionBeginUser;
  PetscCall(PetscMalloc1(nloc, &idx));
  /* p->constrained is sorted: built by a loop over the owned DOFs */
  for (PetscInt k = 0; k < nloc; k++) {
    if (c < p->nconstrained && p->constrained[c] == r0 + k) {
      c++;
      continue;
    }
    idx[n++] = r0 + k;
  }
  PetscCall(ISCreateGeneral(p->comm, n, idx, PETSC_OWN_POINTER, is));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Shares of kinetic energy per component, effective modal masses per direction, and the kind. */
static PetscErrorCode Classify(PeriProblem p, Vec x, Vec mdiag, PeriMode *mode, PetscInt axis)
{
  const PetscInt     bs = p->model->dofs, nloc = p->bonds.rend - p->bonds.rstart;
  const PetscScalar *xa, *ma;
  PetscReal          e[PERI_MAX_DOF + 4] = {0}, tot = 0, trans = 0, rot = 0, along = 0;
  PetscInt           comp[3];

  PetscFunctionBeginUser;
  for (PetscInt d = 0; d < 3; d++) {
    static const char *const names[] = {"ux", "uy", "uz"};
    PetscCall(PeriModelComponentIndex(p->model, names[d], &comp[d]));
  }
  PetscCall(VecGetArrayRead(x, &xa));
  PetscCall(VecGetArrayRead(mdiag, &ma));
  for (PetscInt i = 0; i < nloc; i++)
    for (PetscInt c = 0; c < bs; c++) {
      PetscReal v = PetscRealPart(xa[i * bs + c]), m = PetscRealPart(ma[i * bs + c]);
      e[c] += m * v * v;
      for (PetscInt d = 0; d < 3; d++)
        if (comp[d] == c) e[PERI_MAX_DOF + d] += m * v; /* participation in a unit translation */
    }
  PetscCall(VecRestoreArrayRead(x, &xa));
  PetscCall(VecRestoreArrayRead(mdiag, &ma));
  PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, e, PERI_MAX_DOF + 3, MPIU_REAL, MPI_SUM, p->comm));
  for (PetscInt c = 0; c < bs; c++) tot += e[c];
  for (PetscInt c = 0; c < bs; c++) {
    mode->energy_share[c] = e[c] / tot;
    if (p->model->rotational[c])
      rot += e[c] / tot;
    else
      trans += e[c] / tot;
    if (c == comp[axis]) along = e[c] / tot;
  }
  /* effective mass = (phi^T M r)^2 / (phi^T M phi), as a fraction of the total mass */
  for (PetscInt d = 0; d < 3; d++) mode->effective_mass[d] = comp[d] >= 0 ? e[PERI_MAX_DOF + d] * e[PERI_MAX_DOF + d] / tot / p->modal->total_mass : 0;
  /* A mode that moves the mass as a whole moves it along the axis (axial) or across it (flexural);
   * symmetric structures separate the two exactly. Modes with no net momentum are told apart by
   * where their kinetic energy is. */
  {
    PetscReal maxis = mode->effective_mass[axis], macross = 0;
    for (PetscInt d = 0; d < p->particles.dim; d++)
      if (d != axis) macross = PetscMax(macross, mode->effective_mass[d]);
    if (rot > 0.5)
      PetscCall(PetscStrncpy(mode->kind, "rotational", sizeof(mode->kind)));
    else if (PetscMax(maxis, macross) > 1e-3 ? maxis > macross : along > 0.5 * trans)
      PetscCall(PetscStrncpy(mode->kind, p->particles.dim == 2 ? "axial" : "longitudinal", sizeof(mode->kind)));
    else
      PetscCall(PetscStrncpy(mode->kind, p->particles.dim == 2 ? "flexural" : "transverse", sizeof(mode->kind)));
  }
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* Gathers the full mode vector to rank 0, scaled to max |u| = 1. */
static PetscErrorCode StoreShape(PeriProblem p, Vec full, PetscInt k)
{
  VecScatter         sc;
  Vec                all;
  const PetscScalar *a;
  const PetscInt     nd = p->particles.n * p->model->dofs;

  PetscFunctionBeginUser;
  PetscCall(VecScatterCreateToZero(full, &sc, &all));
  PetscCall(VecScatterBegin(sc, full, all, INSERT_VALUES, SCATTER_FORWARD));
  PetscCall(VecScatterEnd(sc, full, all, INSERT_VALUES, SCATTER_FORWARD));
  if (p->rank == 0) {
    PetscReal amax = 0, *s = &p->modal->shapes[k * nd];
    PetscBool trans = PETSC_FALSE;
    for (PetscInt c = 0; c < p->model->dofs; c++) trans = (PetscBool)(trans || !p->model->rotational[c]);
    PetscCall(VecGetArrayRead(all, &a));
    /* the largest displacement is 1 (rotations, in radians, do not set the scale) */
    for (PetscInt i = 0; i < nd; i++)
      if (!trans || !p->model->rotational[i % p->model->dofs]) amax = PetscMax(amax, PetscAbsReal(PetscRealPart(a[i])));
    for (PetscInt i = 0; i < nd; i++) s[i] = PetscRealPart(a[i]) / (amax > 0 ? amax : 1);
    PetscCall(VecRestoreArrayRead(all, &a));
  }
  PetscCall(VecScatterDestroy(&sc));
  PetscCall(VecDestroy(&all));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriAnalysisRun_Modal - the lowest analysis.nev natural modes (above analysis.target_hz) of the
  constrained body; rigid-body modes of a free body are counted and skipped. Options: every
  -eps_* and -st_* option (e.g. -st_pc_factor_mat_solver_type, -eps_tol). Collective.
@*/
PetscErrorCode PeriAnalysisRun_Modal(PeriProblem p)
{
  PeriModal     *md;
  PetscInt       nev, nfree, nconv, nreq, nd, *order;
  PetscReal      target_hz, scale, sigma, Knorm, *lam;
  Mat            M, Kff, Mff;
  IS             isfree;
  Vec            x, r, y, full, mdiag;
  EPS            eps;
  ST             st;
  KSP            ksp;
  PC             pc;
  PetscLogDouble t0, t1, t2;
  char           what[128];

  PetscFunctionBeginUser;
  PetscCall(ReadSettings(p, &nev, &target_hz));
  PetscCall(SlepcInitialize(NULL, NULL, NULL, NULL));
  PetscCall(PetscStrncpy(p->mat_type, MATAIJ, sizeof(p->mat_type)));
  if (!p->K) PetscCall(PeriProblemAssemble(p));
  PetscCall(PetscTime(&t0));
  PetscCall(PetscLogEventBegin(PERI_EVENT_Solve, 0, 0, 0, 0));
  PetscCall(PeriAssembleMass(p, &M));
  PetscCall(MatCreateVecs(M, &mdiag, NULL));
  PetscCall(MatGetDiagonal(M, mdiag));
  PetscCall(PetscNew(&md));
  p->modal = md;
  /* rotations carry inertia, not mass: the total mass is that of the particles */
  {
    PetscReal *rho;
    PetscCall(Densities(p, &rho));
    for (PetscInt i = p->bonds.rstart; i < p->bonds.rend; i++) md->total_mass += rho[i - p->bonds.rstart] * p->particles.volume[i];
    PetscCall(PetscFree(rho));
  }
  PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, &md->total_mass, 1, MPIU_REAL, MPI_SUM, p->comm));
  md->target_hz = target_hz;
  PetscCall(MainAxis(p, &md->axis));

  PetscCall(FreeDOFs(p, &isfree));
  PetscCall(ISGetSize(isfree, &md->nfree_dofs));
  PetscCheck(md->nfree_dofs > 0, p->comm, PETSC_ERR_USER_INPUT, "%s: every DOF is prescribed: there is no mode to compute", p->scene->file);
  PetscCall(MatCreateSubMatrix(p->K, isfree, isfree, MAT_INITIAL_MATRIX, &Kff));
  PetscCall(MatCreateSubMatrix(M, isfree, isfree, MAT_INITIAL_MATRIX, &Mff));
  PetscCall(MatSetOption(Kff, MAT_SYMMETRIC, PETSC_TRUE));
  PetscCall(MatNorm(Kff, NORM_1, &Knorm));
  PetscCall(PeriRigidMotionFree(p, &nfree, what, sizeof(what), NULL));
  md->nrigid = 0;

  /* the scale of the largest omega^2 */
  {
    PetscReal Mnorm;
    PetscCall(MatNorm(Mff, NORM_1, &Mnorm));
    scale = Knorm / Mnorm;
  }
  sigma = PetscSqr(2 * PETSC_PI * target_hz);
  /* a free body makes K singular: shift just below its zero eigenvalues */
  if (nfree && target_hz == 0) sigma = -1e-8 * scale;
  nreq = PetscMin(nev + nfree, md->nfree_dofs);

  PetscCall(EPSCreate(p->comm, &eps));
  PetscCall(EPSSetOperators(eps, Kff, Mff));
  PetscCall(EPSSetProblemType(eps, EPS_GHEP));
  PetscCall(EPSSetDimensions(eps, nreq, PETSC_DEFAULT, PETSC_DEFAULT));
  PetscCall(EPSSetTarget(eps, sigma));
  PetscCall(EPSSetWhichEigenpairs(eps, EPS_TARGET_MAGNITUDE));
  PetscCall(EPSSetTolerances(eps, 1e-10, PETSC_DEFAULT));
  PetscCall(EPSGetST(eps, &st));
  PetscCall(STSetType(st, STSINVERT));
  PetscCall(STGetKSP(st, &ksp));
  PetscCall(KSPSetType(ksp, KSPPREONLY));
  PetscCall(KSPGetPC(ksp, &pc));
  PetscCall(PCSetType(pc, PCCHOLESKY));
#if defined(PETSC_HAVE_MUMPS)
  PetscCall(PCFactorSetMatSolverType(pc, MATSOLVERMUMPS));
#endif
  PetscCall(EPSSetFromOptions(eps));
  PetscCall(EPSSetUp(eps));
  PetscCall(PetscTime(&t1));
  PetscCall(EPSSolve(eps));
  PetscCall(PetscTime(&t2));
  md->factor_s = t1 - t0;
  md->solve_s  = t2 - t1;
  PetscCall(EPSGetConverged(eps, &nconv));
  PetscCheck(nconv > 0, p->comm, PETSC_ERR_NOT_CONVERGED, "%s: the eigensolver converged no mode (try -eps_ncv, -eps_max_it, or a target with analysis.target_hz)", p->scene->file);

  /* ascending omega^2 */
  PetscCall(PetscMalloc2(nconv, &lam, nconv, &order));
  for (PetscInt k = 0; k < nconv; k++) {
    PetscScalar kr;
    PetscCall(EPSGetEigenvalue(eps, k, &kr, NULL));
    lam[k]   = PetscRealPart(kr);
    order[k] = k;
  }
  PetscCall(PetscSortRealWithPermutation(nconv, lam, order));
  PetscCall(MatCreateVecs(Kff, &x, &r));
  PetscCall(VecDuplicate(r, &y));
  PetscCall(PeriProblemCreateVec(p, &full));
  PetscCall(PetscCalloc1(nev, &md->modes));
  nd          = p->particles.n * p->model->dofs;
  md->nshapes = PetscMin(nev, PERI_MAX_VTU_MODES);
  if (p->rank == 0) PetscCall(PetscCalloc1(md->nshapes * nd, &md->shapes));
  for (PetscInt s = 0; s < nconv && md->nmodes < nev; s++) {
    PetscInt  k = order[s];
    PeriMode *mode;
    PetscReal xn, rn, l = lam[k];
    /* the lowest nfree of a free body are its rigid-body modes, at round-off from zero */
    if (md->nrigid < nfree && PetscAbsReal(l) < 1e-6 * scale) {
      md->nrigid++;
      continue;
    }
    PetscCheck(l > 0, p->comm, PETSC_ERR_NOT_CONVERGED, "%s: a negative eigenvalue omega^2 = %g: the stiffness is indefinite (Poisson ratio above the bond-based value?)", p->scene->file, (double)l);
    mode = &md->modes[md->nmodes];
    PetscCall(EPSGetEigenvector(eps, k, x, NULL));
    /* ||K x - omega^2 M x|| / (||K|| ||x||) */
    PetscCall(MatMult(Kff, x, r));
    PetscCall(MatMult(Mff, x, y));
    PetscCall(VecAXPY(r, -l, y));
    PetscCall(VecNorm(r, NORM_2, &rn));
    PetscCall(VecNorm(x, NORM_2, &xn));
    mode->omega2   = l;
    mode->f_hz     = PetscSqrtReal(l) / (2 * PETSC_PI);
    mode->residual = rn / (Knorm * xn);
    PetscCall(VecSet(full, 0));
    PetscCall(VecISCopy(full, isfree, SCATTER_FORWARD, x));
    PetscCall(Classify(p, full, mdiag, mode, md->axis));
    if (md->nmodes < md->nshapes) PetscCall(StoreShape(p, full, md->nmodes));
    md->nmodes++;
  }
  /* a free bar's lowest longitudinal mode is half a wave over its length */
  if (nfree)
    for (PetscInt k = 0; k < md->nmodes; k++)
      if (!strcmp(md->modes[k].kind, "longitudinal") || !strcmp(md->modes[k].kind, "axial")) {
        PetscReal L            = p->particles.upper[md->axis] - p->particles.lower[md->axis];
        md->longitudinal_speed = 2 * L * md->modes[k].f_hz;
        if (p->particles.dim == 3) md->theory_speed = PetscSqrtReal((p->model->material.K + 4 * p->model->material.G / 3) / p->model->material.rho);
        break;
      }
  PetscCall(PetscLogEventEnd(PERI_EVENT_Solve, 0, 0, 0, 0));
  p->results.solve_s = t2 - t0;
  {
    KSPType kt;
    PCType  pt;
    PetscCall(KSPGetType(ksp, &kt));
    PetscCall(KSPGetPC(ksp, &pc));
    PetscCall(PCGetType(pc, &pt));
    PetscCall(PetscStrncpy(p->results.ksp_type, kt, sizeof(p->results.ksp_type)));
    PetscCall(PetscStrncpy(p->results.pc_type, pt, sizeof(p->results.pc_type)));
    PetscInt asked;
    PetscCall(EPSGetDimensions(eps, &asked, NULL, NULL));
    PetscCall(PetscStrncpy(p->results.converged_reason, nconv >= asked ? "EPS_CONVERGED" : "EPS_PARTIAL", sizeof(p->results.converged_reason)));
    PetscCall(EPSGetIterationNumber(eps, &p->results.iterations));
  }
  md->nshapes = PetscMin(md->nmodes, md->nshapes); /* only converged modes go to particles.vtu */
  PetscCheck(md->nmodes > 0, p->comm, PETSC_ERR_NOT_CONVERGED, "%s: only rigid-body modes converged (%" PetscInt_FMT "): ask for more with analysis.nev", p->scene->file, md->nrigid);
  if (md->nmodes < nev) PetscCall(PetscPrintf(p->comm, "perilin: warning: %" PetscInt_FMT " of the %" PetscInt_FMT " modes asked for converged (the body has %" PetscInt_FMT " free DOFs)\n", md->nmodes, nev, md->nfree_dofs));
  PetscCall(PetscFree2(lam, order));
  PetscCall(VecDestroy(&x));
  PetscCall(VecDestroy(&r));
  PetscCall(VecDestroy(&y));
  PetscCall(VecDestroy(&full));
  PetscCall(VecDestroy(&mdiag));
  PetscCall(EPSDestroy(&eps));
  PetscCall(MatDestroy(&Kff));
  PetscCall(MatDestroy(&Mff));
  PetscCall(MatDestroy(&M));
  PetscCall(ISDestroy(&isfree));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/*@C
  PeriWriteModesCSV - one row per mode: frequency, residual, kind, energy shares, effective
  masses. Rank 0 writes (temporary name, then rename). Collective.
@*/
PetscErrorCode PeriWriteModesCSV(PeriProblem p, const char path[])
{
  char  tmp[PETSC_MAX_PATH_LEN];
  FILE *fp;
  int   bad = 0;

  PetscFunctionBeginUser;
  if (p->rank || !p->modal) PetscFunctionReturn(PETSC_SUCCESS);
  PetscCall(PeriFileOpenTemporary(path, tmp, sizeof(tmp), &fp));
  bad |= fprintf(fp, "mode,f_hz,omega2,residual,kind") < 0;
  for (PetscInt c = 0; c < p->model->dofs; c++) bad |= fprintf(fp, ",share_%s", p->model->components[c]) < 0;
  bad |= fprintf(fp, ",meff_x,meff_y,meff_z\n") < 0;
  for (PetscInt k = 0; k < p->modal->nmodes; k++) {
    const PeriMode *m = &p->modal->modes[k];
    bad |= fprintf(fp, "%" PetscInt_FMT ",%.10g,%.10g,%.3g,%s", k + 1, (double)m->f_hz, (double)m->omega2, (double)m->residual, m->kind) < 0;
    for (PetscInt c = 0; c < p->model->dofs; c++) bad |= fprintf(fp, ",%.6f", (double)m->energy_share[c]) < 0;
    bad |= fprintf(fp, ",%.6f,%.6f,%.6f\n", (double)m->effective_mass[0], (double)m->effective_mass[1], (double)m->effective_mass[2]) < 0;
  }
  PetscCall(PeriFileCloseCommit(fp, tmp, path, bad));
  PetscFunctionReturn(PETSC_SUCCESS);
}
