#!/usr/bin/env python3
"""The pictures of a perilin run (output.plots; src/output/plots.c runs this in a child process).

    draw_plots.py KIND SETDIR OUTDIR [key=value ...]

KIND is quasistatic, modal, anisotropy or dynamic. The script reads the output set's own files in
SETDIR (steps.csv; modes.csv and particles.vtu or .pvtu; anisotropy_polar.csv and
anisotropy_envelope.csv; history.csv and particles.vtu)
and writes PNG files of SIZE pixels into OUTDIR; perilin moves them into the set only when this
exits 0. key=value: facts summary.json will hold, which is written after the pictures. matplotlib's
Agg backend: no display is needed. docs/summary.md lists the files."""
import csv
import math
import os
import re
import struct
import sys

SIZE = (960, 720)  # pixels of every picture; tests/plots.sh checks them
DPI = 100


def pyplot():
    try:
        import matplotlib
        matplotlib.use("Agg")  # headless
        import matplotlib.pyplot as plt
    except ImportError as e:
        sys.exit("matplotlib cannot be imported (%s): install python3-matplotlib" % e)
    return plt


def figure(plt):
    return plt.figure(figsize=(SIZE[0] / DPI, SIZE[1] / DPI), dpi=DPI)


def save(fig, path):
    fig.savefig(path, dpi=DPI, format="png")  # never bbox_inches="tight": the size is fixed


def rows_of(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


# ----------------------------------------------------------------- quasi-static
def draw_load_displacement(plt, u, F, xlabel, ylabel, title, out):
    """The curve through the unloaded state; shared with docs/tools/plot_load_displacement.py."""
    fig = figure(plt)
    ax = fig.add_subplot(1, 1, 1)
    ax.plot(u, F, "o-", ms=3)
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    ax.set_title(title, fontsize=9)
    ax.grid(True, alpha=0.3)
    fig.tight_layout()
    save(fig, out)


def quasistatic(setdir, outdir, facts):
    rows = rows_of(os.path.join(setdir, "steps.csv"))
    col, comp = facts["force"], facts.get("component", "u")
    if not rows or col not in rows[0]:
        sys.exit("steps.csv has no rows or no column %s" % col)
    u = [0.0] + [float(r["control_u"]) for r in rows]
    F = [0.0] + [float(r[col]) for r in rows]
    if col == "reaction":
        ylabel = "reaction of region %s along %s [force]" % (facts.get("region", "?"), comp)
    else:
        ylabel = "applied load along %s, load factor x %s [force]" % (comp, facts.get("load", "?"))
    probe = facts.get("probe")
    xlabel = "%s of probe %s [length]" % (comp, probe) if probe else "%s (no probe: 0) [length]" % comp
    crit = float(facts.get("critical", 0))
    what = ("failed at load factor %.6g (last equilibrium %.6g)" % (crit, float(facts["peak"])) if crit
            else "reached load factor %.6g" % float(facts["peak"]))
    title = "%s; %s bonds broken; peak force %.4g" % (what, facts.get("broken", "?"), max(F, key=abs))
    draw_load_displacement(pyplot(), u, F, xlabel, ylabel, title, os.path.join(outdir, "load_displacement.png"))


# ----------------------------------------------------------------------- modal
def read_vtu(path, names):
    """Points and the named Float64 arrays of a .vtu perilin wrote (raw appended, UInt64 headers)."""
    data = open(path, "rb").read()
    start = data.index(b"<AppendedData")
    start = data.index(b"_", start) + 1
    head = data[:start].decode("latin-1")
    end = "<" if 'byte_order="LittleEndian"' in head else ">"
    out = {}
    for tag in re.findall(r"<DataArray [^>]*>", head):
        name = re.search(r'Name="([^"]*)"', tag).group(1)
        if name not in names or 'type="Float64"' not in tag:
            continue
        ncomp = int(re.search(r'NumberOfComponents="(\d+)"', tag).group(1))
        off = start + int(re.search(r'offset="(\d+)"', tag).group(1))
        nbytes = struct.unpack(end + "Q", data[off:off + 8])[0]
        vals = struct.unpack("%s%dd" % (end, nbytes // 8), data[off + 8:off + 8 + nbytes])
        out[name] = [vals[k:k + ncomp] for k in range(0, len(vals), ncomp)]
    return out


def read_particles(setdir, names):
    """particles.vtu, or the pieces particles.pvtu lists (several ranks); None without either."""
    names = set(names) | {"Points"}
    single = os.path.join(setdir, "particles.vtu")
    if os.path.exists(single):
        return read_vtu(single, names)
    index = os.path.join(setdir, "particles.pvtu")
    if not os.path.exists(index):
        return None
    out = {}
    for piece in re.findall(r'<Piece Source="([^"]+)"', open(index).read()):
        for k, v in read_vtu(os.path.join(setdir, piece), names).items():
            out.setdefault(k, []).extend(v)
    return out


def sketch(ax, X, U, title):
    """A mode shape over the reference positions: the longest axis across, the axis the mode moves
    most along upwards; displacements scaled to 8 % of the body's size."""
    ext = [max(x[d] for x in X) - min(x[d] for x in X) for d in range(3)]
    h = max(range(3), key=lambda d: ext[d])
    v = max((d for d in range(3) if d != h), key=lambda d: (max(abs(u[d]) for u in U), ext[d]))
    s = 0.08 * max(ext)
    step = max(1, len(X) // 20000)
    ax.scatter([x[h] for x in X[::step]], [x[v] for x in X[::step]], s=1, c="0.85", lw=0)
    ax.scatter([x[h] + s * u[h] for x, u in zip(X[::step], U[::step])], [x[v] + s * u[v] for x, u in zip(X[::step], U[::step])], s=1, c="C0", lw=0)
    if ext[2] == 0 and h != 2 and v != 2:
        ax.set_aspect("equal", adjustable="datalim")
    ax.set_title(title, fontsize=8)
    ax.set_xticks([])
    ax.set_yticks([])
    ax.set_xlabel("xyz"[h], fontsize=8)
    ax.set_ylabel("xyz"[v], fontsize=8)


def modal(setdir, outdir, facts):
    modes = rows_of(os.path.join(setdir, "modes.csv"))
    if not modes:
        sys.exit("modes.csv has no mode")
    plt = pyplot()
    fig = figure(plt)
    shown = modes[:6]
    P = read_particles(setdir, ["mode_%s" % m["mode"] for m in shown])
    shapes = [m for m in shown if P and ("mode_%s" % m["mode"]) in P]
    top = fig.add_subplot(2 if shapes else 1, 1, 1)
    f = [float(m["f_hz"]) for m in modes]
    n = list(range(1, len(f) + 1))
    top.stem(n, f)
    for k, m in zip(n, modes):
        top.annotate("%.4g\n%s" % (float(m["f_hz"]), m["kind"]), (k, float(m["f_hz"])), textcoords="offset points", xytext=(0, 4), ha="center", fontsize=7)
    top.set_xlabel("mode (modes.csv)")
    top.set_ylabel("frequency [1/time]")
    top.set_xticks(n)
    top.set_ylim(0, 1.25 * max(f))
    top.set_title("%d natural frequencies" % len(f), fontsize=9)
    top.grid(True, alpha=0.3)
    for k, m in enumerate(shapes):
        ax = fig.add_subplot(4, 3, 7 + k)
        sketch(ax, P["Points"], P["mode_%s" % m["mode"]], "mode %s: %.4g, %s" % (m["mode"], float(m["f_hz"]), m["kind"]))
    fig.tight_layout()
    save(fig, os.path.join(outdir, "modes.png"))


# --------------------------------------------------------------------- dynamic
def dynamic(setdir, outdir, facts):
    """The energies against time, the fronts (history.csv has them with analysis.fronts), and the
    last state: its damage where the scene has failure, else its speed |v|."""
    rows = rows_of(os.path.join(setdir, "history.csv"))
    if not rows:
        sys.exit("history.csv has no rows")
    plt = pyplot()
    fig = figure(plt)
    t = [float(r["time"]) for r in rows]
    fronts = "wave_front" in rows[0]
    P = read_particles(setdir, ["damage", "velocity"])
    field = "damage" if P and "damage" in P else ("velocity" if P and "velocity" in P else None)
    n = 1 + fronts + (field is not None)
    ax = fig.add_subplot(n, 1, 1)
    for col in ("kinetic", "strain", "dissipated", "work"):
        ax.plot(t, [float(r[col]) for r in rows], label=col)
    E0 = float(rows[0]["balance"])
    ax.plot(t, [float(r["balance"]) - E0 for r in rows], "k--", label="balance - balance(0)")
    ax.set_xlabel("time")
    ax.set_ylabel("energy")
    ax.set_title("%s dynamics: energy drift %s, %s bonds broken" % (facts.get("integrator", "?"), facts.get("drift", "?"), rows[-1]["broken"]), fontsize=9)
    ax.legend(fontsize=7)
    ax.grid(True, alpha=0.3)
    if fronts:
        ax = fig.add_subplot(n, 1, 2)
        for col in ("wave_front", "damage_front"):
            ax.plot(t, [float(r[col]) for r in rows], label=col)
        ax.set_xlabel("time")
        ax.set_ylabel("distance from the origin")
        ax.legend(fontsize=7)
        ax.grid(True, alpha=0.3)
    if field:
        ax = fig.add_subplot(n, 1, n)
        X = P["Points"]
        c = [v[0] for v in P[field]] if field == "damage" else [math.sqrt(sum(x * x for x in v)) for v in P[field]]
        step = max(1, len(X) // 40000)
        sc = ax.scatter([x[0] for x in X[::step]], [x[1] for x in X[::step]], c=c[::step], s=1, lw=0, cmap="viridis")
        fig.colorbar(sc, ax=ax)
        ax.set_aspect("equal", adjustable="datalim")
        ax.set_title("t = %g: %s (x, y; a 3D body seen along z)" % (t[-1], field if field == "damage" else "|velocity|"), fontsize=8)
    fig.tight_layout()
    save(fig, os.path.join(outdir, "dynamics.png"))


# ------------------------------------------------------------------ anisotropy
def anisotropy(setdir, outdir, facts):
    plt = pyplot()
    polar = rows_of(os.path.join(setdir, "anisotropy_polar.csv"))
    env = rows_of(os.path.join(setdir, "anisotropy_envelope.csv"))
    crits = list(dict.fromkeys(r["criterion"] for r in polar))
    paths = list(dict.fromkeys((r["s1"], r["s2"]) for r in polar))[:4]
    ms = list(dict.fromkeys(r["m"] for r in polar))
    # polar: the failure load of the lattice over the continuum's against the orientation Theta
    fig = figure(plt)
    for i, c in enumerate(crits):
        for j, p in enumerate(paths):
            ax = fig.add_subplot(len(crits), len(paths), i * len(paths) + j + 1, projection="polar")
            top = 1.01
            for k, m in enumerate(ms):
                pts = [(math.radians(float(r["theta_deg"])), float(r["ratio"])) for r in polar
                       if r["criterion"] == c and (r["s1"], r["s2"]) == p and r["m"] == m and math.isfinite(float(r["ratio"]))]
                if pts:
                    top = max(top, max(v for _, v in pts))
                    ax.plot([t for t, _ in pts], [v for _, v in pts], color="C%d" % k, lw=1, label="m = %s" % m)
            # the circle of 1 (lattice and continuum agree) at a third of the radius
            ax.set_ylim(1 - (top - 1) / 2, top + (top - 1) / 20)
            ax.set_yticks([1, round(top, 3)])
            ax.set_thetamin(0)
            ax.set_thetamax(90)
            ax.tick_params(labelsize=6)
            ax.set_title("%s, [%s, %s]" % (c, p[0], p[1]), fontsize=8)
    handles, labels = fig.axes[0].get_legend_handles_labels() if fig.axes else ([], [])
    fig.legend(handles, labels, loc="lower center", ncol=len(ms), fontsize=8)
    fig.suptitle("lattice failure load / continuum failure load against the orientation Theta (inner tick: 1)", fontsize=10)
    fig.tight_layout(rect=(0, 0.05, 1, 0.95))
    save(fig, os.path.join(outdir, "anisotropy_polar.png"))
    # envelopes: where the continuum and the lattice (its strongest orientation) fail in (s1, s2)
    fig = figure(plt)
    ecrits = list(dict.fromkeys(r["criterion"] for r in env))
    for i, c in enumerate(ecrits):
        ax = fig.add_subplot(1, len(ecrits), i + 1)
        mine = [r for r in env if r["criterion"] == c]
        for k, m in enumerate(ms):
            line(ax, [r for r in mine if r["m"] == m], "lattice_max", dict(color="C%d" % k, lw=1, label="lattice m = %s" % m))
        line(ax, [r for r in mine if r["m"] == ms[0]], "continuum", dict(color="k", lw=1.5, label="continuum"))
        ax.axhline(0, color="0.7", lw=0.5)
        ax.axvline(0, color="0.7", lw=0.5)
        ax.set_aspect("equal", adjustable="datalim")
        ax.set_xlabel("s1 / critical stretch")
        ax.set_ylabel("s2 / critical stretch")
        ax.set_title(c, fontsize=9)
        ax.tick_params(labelsize=7)
    if fig.axes:
        fig.axes[0].legend(fontsize=7)
    fig.suptitle("failure envelopes in the principal stretches: continuum, lattice at its strongest orientation", fontsize=10)
    fig.tight_layout(rect=(0, 0, 1, 0.95))
    save(fig, os.path.join(outdir, "anisotropy_envelope.png"))


def line(ax, rows, col, style):
    """The envelope r(psi) (s1, s2) = r (cos psi, sin psi), broken where nothing fails."""
    xs, ys = [], []
    for r in rows + rows[:1]:  # closed
        v, psi = float(r[col]), math.radians(float(r["psi_deg"]))
        xs.append(v * math.cos(psi) if math.isfinite(v) else math.nan)
        ys.append(v * math.sin(psi) if math.isfinite(v) else math.nan)
    ax.plot(xs, ys, **style)


def main():
    if len(sys.argv) < 4 or sys.argv[1] not in ("quasistatic", "modal", "anisotropy", "dynamic"):
        sys.exit(__doc__)
    facts = dict(a.split("=", 1) for a in sys.argv[4:])
    globals()[sys.argv[1]](sys.argv[2], sys.argv[3], facts)


if __name__ == "__main__":
    main()
