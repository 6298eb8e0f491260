# The crack angles of a Kalthoff-Winkler run (docs/contact.md): python3 docs/tools/kw_angle.py OUTPUT_DIR
# (from the repository). Damaged particles (damage > 0.35) within 40 mm of each notch tip, a
# least-squares line through the tip; the angle from the notch (the x axis).
import sys, math
sys.path.insert(0,'src/output')
from draw_plots import read_particles
P=read_particles(sys.argv[1],['damage'])
X=P['Points']; D=[d[0] for d in P['damage']]
# upper crack: damaged particles right of the tip (0.05, 0.025), above y=0.025, within 40 mm of the tip
pts=[(x[0]-0.05,x[1]-0.025) for x,d in zip(X,D) if d>0.35 and x[0]>0.052 and x[1]>0.027 and math.hypot(x[0]-0.05,x[1]-0.025)<0.04]
if not pts: print('no crack'); sys.exit()
# angle of each point from the tip, weighted: least-squares line through the tip
sxx=sum(a*a for a,b in pts); sxy=sum(a*b for a,b in pts); syy=sum(b*b for a,b in pts)
ang=0.5*math.degrees(math.atan2(2*sxy, sxx-syy))
print('upper crack: %d particles, angle from the notch %.1f deg'%(len(pts),ang))
pts=[(x[0]-0.05,-(x[1]+0.025)) for x,d in zip(X,D) if d>0.35 and x[0]>0.052 and x[1]<-0.027 and math.hypot(x[0]-0.05,x[1]+0.025)<0.04]
sxx=sum(a*a for a,b in pts); sxy=sum(a*b for a,b in pts); syy=sum(b*b for a,b in pts)
print('lower crack: %d particles, angle %.1f deg'%(len(pts),0.5*math.degrees(math.atan2(2*sxy, sxx-syy))))
