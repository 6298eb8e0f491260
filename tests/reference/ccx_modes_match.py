"""Matches perilin's modes (summary.json modal.modes) to CalculiX's free-bar reference
(tests/reference/ccx_free_bar.json) by kind, one to one: each reference mode, in the order of the
reference, to the nearest perilin mode in frequency of the same kind not matched before. The kind
comes from the energy shares: axial -> longitudinal (or ux above 0.6); bending about one axis moves
the bar in one transverse direction only (the bar's symmetry makes the other share round-off:
below 0.05), z or y by the larger share; torsion -> the rest, whose shares split between uy and uz
(about 0.2 and 0.8 on this cross-section). Used by tests/perf/lps_ccx.sh and tests/lps_surface.py."""
import json


def kind(mode):
    s = mode["energy_share"]
    if mode["kind"] == "longitudinal" or s["ux"] > 0.6:
        return "axial"
    if min(s["uy"], s["uz"]) < 0.05:
        return "bending-z" if s["uz"] > s["uy"] else "bending-y"
    return "torsion"


def reference(path, nu):
    """(frequencies in Hz, their types) of the converged CalculiX case at this nu"""
    case = json.load(open(path))["cases"][str(float(nu))]
    return case["freq_hz"], case["types"]


def match(modes, ref_freqs, ref_types):
    """[(type, reference Hz, perilin Hz or None)] for every reference mode"""
    rows, used = [], set()
    for f, t in zip(ref_freqs, ref_types):
        cand = [k for k, m in enumerate(modes) if kind(m) == t.split()[0] and k not in used]
        best = min(cand, key=lambda k: abs(modes[k]["f_hz"] - f)) if cand else None
        used.add(best)
        rows.append((t, f, None if best is None else modes[best]["f_hz"]))
    return rows
