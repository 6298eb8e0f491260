# Where a running crack branches (docs/dynamics.md, "Crack branching in glass"):
#   python3 docs/tools/branch_point.py OUTPUT_DIR [--damage 0.35] [--png FILE] [--frames]
# (from the repository). Reads particles.vtu (or .pvtu) of a 2D run with failure, column by
# column along x: the particles damaged more than --damage in a column are split into clusters
# along y (a gap of more than 1.5 spacings between them: at least one undamaged particle). The
# crack is one branch where a column has one cluster and two where it has two or more, one on
# each side of the crack's line (y = y_line, the pre-crack's, default 0). The branch point is the
# first column of the first run of at least --run (default 1 mm) of columns with two branches. Also
# prints the crack tip (the largest x with damage), the branches' separation at the tip and, with
# --frames, the same per frame of particles.pvd with its time (when the branches appear). With
# history.csv's damage_front (analysis.fronts from the pre-crack's tip), the crack speed before
# branching: the least-squares slope of the front over the rows where it has left the tip and not
# yet passed the branch point, and over the last --window (default 5 us) before it.
import argparse, math, os, re, sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "src", "output"))
from draw_plots import read_particles, read_vtu


def analyse(X, D, thr, y_line, run_len):
    xs = sorted(set(round(x[0], 12) for x in X))
    h = min(b - a for a, b in zip(xs, xs[1:]))
    cols = {}
    for x, d in zip(X, D):
        if d > thr:
            cols.setdefault(round(x[0], 12), []).append(x[1])
    res = {"h": h, "tip": max(cols) if cols else None, "branch": None, "separation": None, "columns": {}}
    for cx in sorted(cols):
        ys = sorted(cols[cx])
        clusters = [[ys[0], ys[0]]]
        for y in ys[1:]:
            if y - clusters[-1][1] > 1.5 * h:
                clusters.append([y, y])
            else:
                clusters[-1][1] = y
        two = len(clusters) >= 2 and clusters[0][0] < y_line < clusters[-1][1] and \
            any(c[1] < y_line for c in clusters) and any(c[0] > y_line for c in clusters)
        res["columns"][cx] = (two, clusters)
    run_start, run = None, 0.0
    for cx in sorted(res["columns"]):
        if res["columns"][cx][0]:
            if run_start is None:
                run_start = cx
            if cx - run_start + h >= run_len - 1e-12:
                res["branch"] = run_start
                break
        else:
            run_start = None
    if res["tip"] is not None and res["branch"] is not None:
        # separation of the outermost clusters, averaged over the last 1 mm of two-branch columns
        last = [cx for cx in res["columns"] if res["columns"][cx][0] and cx > res["branch"]]
        if last:
            top = max(last)
            sel = [cx for cx in last if cx > top - 1e-3]
            res["separation"] = sum(res["columns"][cx][1][-1][0] - res["columns"][cx][1][0][1] for cx in sel) / len(sel)
    return res


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("dir")
    ap.add_argument("--damage", type=float, default=0.35)
    ap.add_argument("--line", type=float, default=0.0, help="y of the crack's line")
    ap.add_argument("--run", type=float, default=1e-3, help="length of two-branch columns that makes a branch [length]")
    ap.add_argument("--origin", type=float, default=0.0, help="analysis.fronts.origin (x of the pre-crack's tip)")
    ap.add_argument("--window", type=float, default=5e-6, help="the last stretch of time before branching over which the speed is also fitted [time]")
    ap.add_argument("--png")
    ap.add_argument("--frames", action="store_true")
    a = ap.parse_args()
    P = read_particles(a.dir, ["damage"])
    if P is None or "damage" not in P:
        sys.exit("%s: no particles.vtu with damage" % a.dir)
    X, D = P["Points"], [d[0] for d in P["damage"]]
    r = analyse(X, D, a.damage, a.line, a.run)
    fmt = lambda v: "none" if v is None else "%.2f mm" % (1e3 * v)
    print("spacing %.4g mm, damage > %g: crack tip x = %s, branch point x = %s, branch separation at the tip %s"
          % (1e3 * r["h"], a.damage, fmt(r["tip"]), fmt(r["branch"]), fmt(r["separation"])))
    hist = os.path.join(a.dir, "history.csv")
    if os.path.exists(hist) and r["branch"] is not None:
        rows = [l.strip().split(",") for l in open(hist)]
        if "damage_front" in rows[0]:
            c = rows[0].index("damage_front")
            pts = [(float(w[0]), float(w[c])) for w in rows[1:] if 0 < float(w[c]) <= r["branch"] - a.origin]
            if len(pts) > 1:
                n = len(pts)
                st, sx = sum(t for t, x in pts), sum(x for t, x in pts)
                stt, stx = sum(t * t for t, x in pts), sum(t * x for t, x in pts)
                v = (n * stx - st * sx) / (n * stt - st * st)
                print("crack speed before branching %.0f m/s (damage_front, %d rows, t = %.2f to %.2f us); "
                      "the front reaches the branch point at %.2f us" % (v, n, 1e6 * pts[0][0], 1e6 * pts[-1][0], 1e6 * pts[-1][0]))
                late = [(t, x) for t, x in pts if t >= pts[-1][0] - a.window]
                if len(late) > 1:
                    n = len(late)
                    st, sx = sum(t for t, x in late), sum(x for t, x in late)
                    stt, stx = sum(t * t for t, x in late), sum(t * x for t, x in late)
                    print("crack speed over the last %.3g us before branching %.0f m/s" % (1e6 * a.window, (n * stx - st * sx) / (n * stt - st * st)))
    if a.frames:
        pvd = os.path.join(a.dir, "particles.pvd")
        for t, f in re.findall(r'timestep="([^"]+)"[^>]*file="([^"]+)"', open(pvd).read()):
            Q = read_vtu(os.path.join(a.dir, f), {"Points", "damage"})
            if "damage" not in Q:
                continue
            q = analyse(Q["Points"], [d[0] for d in Q["damage"]], a.damage, a.line, a.run)
            print("t = %6.2f us: tip %s, branch point %s" % (1e6 * float(t), fmt(q["tip"]), fmt(q["branch"])))
    if a.png:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        fig, ax = plt.subplots(figsize=(10, 4.4))
        sc = ax.scatter([1e3 * x[0] for x in X], [1e3 * x[1] for x in X], c=D, s=0.6, lw=0, cmap="viridis", vmin=0, vmax=0.5)
        if r["branch"] is not None:
            ax.axvline(1e3 * r["branch"], color="r", lw=0.6)
        ax.set_aspect("equal")
        ax.set_xlabel("x [mm]")
        ax.set_ylabel("y [mm]")
        fig.colorbar(sc, ax=ax, label="damage", shrink=0.8)
        fig.savefig(a.png, dpi=150, bbox_inches="tight")


if __name__ == "__main__":
    main()
