#!/usr/bin/env python3
"""Homogenized stiffness of the 2D bond-based PMB lattice (plane stress, unit spacing) for each
partial-volume rule: the uniaxial-stress strain e_xx E / sigma and Poisson ratio of the discrete
sum C_ijkl = (c/2) sum_j alpha_j V_j |xi_j| e_i e_j e_k e_l, and the discrete horizon volume
V(H) = V_i + sum_j alpha_j V_j relative to pi delta^2. Exact elasticity gives 1, 1/3 and 1.
Regenerates the table in docs/theory.md:  python3 docs/tools/lattice_table.py"""
import math
def alpha(r,d,h,mode):
    if mode=='none': return 1.0 if r<=d*(1+1e-10) else 0
    if mode=='linear' and r>d*(1+1e-10): return 0
    if mode=='cont' and r>=d+h/2: return 0
    if r<=d-h/2: return 1
    return min(1,(d+h/2-r)/h)
print("| m | none: e_xx E/σ | none: ν | linear (cut): e_xx E/σ | cut: ν | linear_continued: e_xx E/σ | continued: ν | V(H)/πδ² none | cut | continued |")
print("|---|---|---|---|---|---|---|---|---|---|")
for m in [1.5,2,3,3.015,4,5,6]:
  row=[str(m)]; vols=[]
  for mode in ['none','linear','cont']:
    d=m; c11=c12=c22=0; V=0
    R=int(m+2)
    for i in range(-R,R+1):
      for j in range(-R,R+1):
        if i==0 and j==0: continue
        r=math.hypot(i,j); a=alpha(r,d,1,mode)
        if a==0: continue
        ex,ey=i/r,j/r
        c11+=a*r*ex**4; c12+=a*r*ex*ex*ey*ey; c22+=a*r*ey**4; V+=a
    k=9/(math.pi*d**3)/2
    c11*=k;c12*=k;c22*=k
    det=c11*c22-c12*c12; exx=c22/det; eyy=-c12/det
    row+=['%.4f'%exx,'%.4f'%(-eyy/exx)]; vols.append('%.4f'%((V+1)/(math.pi*d*d)))
  print('| '+' | '.join(row+vols)+' |')
