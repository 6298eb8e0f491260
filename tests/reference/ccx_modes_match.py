"""Matches perilin's modes (summary.json modal.modes) to CalculiX's free-bar reference
(tests/reference/ccx_free_bar.json) by kind: each reference mode to the perilin mode of the same kind
(the direction of the largest energy share: bending z -> uz above 0.895, bending y -> uy above 0.8,
axial -> longitudinal; torsion -> the rest, whose shares split between uy and uz) nearest in
frequency. Used by tests/perf/lps_ccx.sh and tests/lps_surface.py."""
import json


def kind(mode):
    s = mode["energy_share"]
    if mode["kind"] == "longitudinal" or s["ux"] > 0.6:
        return "axial"
    if s["uz"] > 0.895:
        return "bending-z"
    if s["uy"] > 0.8:
        return "bending-y"
    return "torsion"


def reference(path, nu):
    """(frequencies in Hz, their types) of the converged CalculiX case at this nu"""
    case = json.load(open(path))["cases"][str(float(nu))]
    return case["freq_hz"], case["types"]


def match(modes, ref_freqs, ref_types):
    """[(type, reference Hz, perilin Hz or None)] for every reference mode"""
    rows = []
    for f, t in zip(ref_freqs, ref_types):
        cand = [m["f_hz"] for m in modes if kind(m) == t.split()[0]]
        rows.append((t, f, min(cand, key=lambda x: abs(x - f)) if cand else None))
    return rows
