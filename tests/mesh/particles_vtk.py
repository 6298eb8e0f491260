"""A run's particles.vtu (one rank) or particles.pvtu (one piece per rank) read by VTK's own
readers: the positions and a getter for point arrays, as NumPy arrays (tests/mesh/kt.py,
tests/mesh/stochastic.py)."""
import os

from vtkmodules.util.numpy_support import vtk_to_numpy
from vtkmodules.vtkIOXML import vtkXMLPUnstructuredGridReader, vtkXMLUnstructuredGridReader


def read(run):
    """(X, array): X the positions (n x 3), array(name) the named point array."""
    parallel = os.path.exists(run + "/particles.pvtu")
    r = vtkXMLPUnstructuredGridReader() if parallel else vtkXMLUnstructuredGridReader()
    r.SetFileName(run + ("/particles.pvtu" if parallel else "/particles.vtu"))
    r.Update()
    g = r.GetOutput()
    X = vtk_to_numpy(g.GetPoints().GetData()).astype(float)
    return X, lambda name: vtk_to_numpy(g.GetPointData().GetArray(name)).astype(float)
