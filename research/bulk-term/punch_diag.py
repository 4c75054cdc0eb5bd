"""Diagnostic: the punch (1 mm, one step) with the rule of lbulk.py (beta 0.3, c_h 0.5, c_l 1, B_ij 0.01 E,
anchor 10/1.5), one plain iteration at a time, for a capsule/aux corotation form:
corot (aux fields corotated with the capsule's 1-ring rotations), corot-scale (each level with rotations
fitted over its own balls), corot-thick (one rotation per node over a ball of C_R h), corot-skin (aux not
corotated), membrane. Usage: punch_diag.py form iterations"""
import numpy as np, sys, os
from lbulk import *
p = Punch(); h = np.loadtxt(D + "punch_thickness.txt")
n = len(p.X); mask = np.zeros((n, 3), bool); mask[p.moved] = True
cn = (mask | p.fixed).all(1).astype(float)
corot = sys.argv[1] in ("corot", "corot-skin", "corot-scale", "corot-thick"); itm = int(sys.argv[2])
lb = LBulk(p.X, p.T, p.fixed, h, beta=0.3, c_h=0.5, c_l=1, bij=0.01, corot=corot, aux_corot={"corot": True, "corot-scale": "scale", "corot-thick": "thick"}.get(sys.argv[1], False), anchor=(10, 1.5, cn))
vals = np.zeros((n, 3)); vals[p.moved, 2] = -0.001
u = np.zeros((n, 3))
for k in range(itm):
    u, it, du = lb.solve(u, mask, vals, it_max=1, tol=1e-10, anderson=0) if not corot else lb.solve(u, mask, vals, it_max=1, tol=1e-10, anderson=0)
    p.report(f"{sys.argv[1]} iteration {k+1} du {du:.1e}", lb.m, u, force=-lb.reaction[p.moved, 2].sum())
