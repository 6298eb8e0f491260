# The crack angles of a Kalthoff-Winkler run (docs/contact.md), from the repository:
#     python3 docs/tools/kw_angle.py OUTPUT_DIR [NOTCH_Y]
# NOTCH_Y: the notches' distance from the mid-line (default 0.025; the 3D example's 0.024), their
# tips at x = 0.05. The damaged particles (damage > 0.35) within 40 mm of each tip, beyond it, a
# least-squares line through the tip: its angle from the notch (the x axis). A 3D body is seen
# along z (every layer counts).
import math
import sys

sys.path.insert(0, "src/output")
from draw_plots import read_particles  # noqa: E402

out = sys.argv[1]
y0 = float(sys.argv[2]) if len(sys.argv) > 2 else 0.025
P = read_particles(out, ["damage"])
X, D = P["Points"], [d[0] for d in P["damage"]]
for sign, name in ((1, "upper"), (-1, "lower")):
    pts = [(x[0] - 0.05, sign * x[1] - y0) for x, d in zip(X, D) if d > 0.35 and x[0] > 0.052 and sign * x[1] > y0 + 0.002 and math.hypot(x[0] - 0.05, sign * x[1] - y0) < 0.04]
    if not pts:
        print("%s crack: none" % name)
        continue
    sxx = sum(a * a for a, b in pts)
    sxy = sum(a * b for a, b in pts)
    syy = sum(b * b for a, b in pts)
    print("%s crack: %d particles, angle from the notch %.1f deg" % (name, len(pts), 0.5 * math.degrees(math.atan2(2 * sxy, sxx - syy))))
