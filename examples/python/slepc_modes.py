"""perilin's stiffness K and lumped mass M of a modal scene, solved with slepc4py under your own
options, against the frequencies perilin's modal analysis computes itself (docs/python.md).

usage: /usr/bin/python3 examples/python/slepc_modes.py [SCENE] [PETSc/SLEPc options]
       (default SCENE: examples/lamina/modal.yaml; e.g. -eps_type krylovschur -eps_tol 1e-12)
Prints both sets of frequencies; exits 1 when they differ by more than 1e-8 (relative).
"""
import os
import sys

import petsc4py
import slepc4py

args = sys.argv[1:]
scene = args.pop(0) if args and not args[0].startswith("-") else os.path.join(os.path.dirname(__file__), "..", "lamina", "modal.yaml")
petsc4py.init([sys.argv[0]] + args)  # your options go to PETSc and SLEPc, before perilin starts
slepc4py.init([sys.argv[0]] + args)
import numpy as np
from petsc4py import PETSc
from slepc4py import SLEPc

import perilin

p = perilin.Problem(scene, {"output.plots": False})
nev = int(p.get("analysis.nev"))
own = p.solve().summary["modal"]["frequencies_hz"]  # perilin's modal analysis

# K and M on the free DOFs, as perilin's modal analysis gives them to SLEPc
K, m, free = p.stiffness(), p.mass(), p.free_dofs()
Kff = K.createSubMatrix(free, free)
mf = m.getSubVector(free)
M = PETSc.Mat().createAIJ(Kff.getSizes(), nnz=(1, 0), comm=K.getComm())
M.setDiagonal(mf)
M.assemble()
symmetric = Kff.isSymmetric(1e-10 * Kff.norm(PETSc.NormType.INFINITY))

eps = SLEPc.EPS().create(comm=K.getComm())
eps.setOperators(Kff, M)
eps.setProblemType(SLEPc.EPS.ProblemType.GHEP if symmetric else SLEPc.EPS.ProblemType.GNHEP)
eps.setDimensions(nev)
eps.setTarget(0.0)
eps.setWhichEigenpairs(SLEPc.EPS.Which.TARGET_MAGNITUDE)
st = eps.getST()
st.setType(SLEPc.ST.Type.SINVERT)  # shift-and-invert at 0: the lowest modes first
st.getKSP().setType("preonly")
st.getKSP().getPC().setType("lu")
if K.getComm().getSize() > 1:
    st.getKSP().getPC().setFactorSolverType("mumps")
eps.setTolerances(1e-12)
eps.setFromOptions()
eps.solve()
lam = sorted(eps.getEigenvalue(k).real for k in range(min(nev, eps.getConverged())))
mine = [np.sqrt(max(l, 0.0)) / (2 * np.pi) for l in lam]

rel = max(abs(a - b) / b for a, b in zip(mine, own)) if len(mine) == len(own) else np.inf
if K.getComm().getRank() == 0:
    print("K: %d free DOFs of %d, %s; M: the lumped mass" % (Kff.getSize()[0], K.getSize()[0], "symmetric" if symmetric else "unsymmetric"))
    print("mode  slepc4py (Hz)  perilin (Hz)")
    for k, (a, b) in enumerate(zip(mine, own)):
        print("%4d  %13.6f  %12.6f" % (k + 1, a, b))
    print("%s: largest relative difference %.2g (<= 1e-8)" % ("ok" if rel <= 1e-8 else "FAIL", rel))
p.close()
sys.exit(0 if rel <= 1e-8 else 1)
