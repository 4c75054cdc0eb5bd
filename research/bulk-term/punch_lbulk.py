"""The flat punch with lbulk.py's aux-field bulk (+ anchor), the engine's way: 4 steps, geometry
and the capsule's rotations updated per iteration (Anderson), corotational or membrane capsule.
Usage: punch_lbulk.py beta c_h Bij/E c_l corot|membrane [beta_a,c_a]"""
import numpy as np, sys, time, os
from lbulk import *
p = Punch(); h = np.loadtxt(D + "punch_thickness.txt")
beta, ch, bij, cl = (float(x) for x in sys.argv[1:5]); form = sys.argv[5]
anc = [float(x) for x in sys.argv[6].split(",")] if len(sys.argv) > 6 else None
n = len(p.X); mask = np.zeros((n, 3), bool); mask[p.moved] = True
cn = (mask | p.fixed).all(1).astype(float)
t = time.time()
lb = LBulk(p.X, p.T, p.fixed, h, beta=beta, c_h=ch, c_l=cl, bij=bij, corot=(form in ("corot", "corot-skin", "corot-scale", "corot-thick")), aux_corot={"corot": True, "corot-scale": "scale", "corot-thick": "thick"}.get(form, False),
           anchor=(anc[0], anc[1], cn) if anc else None)
print(lb.stats(), flush=True)
u, its, F = run_punch(p, lb, steps=4, it_max=80, tol=1e-10)
p.report(f"{form} aux b {beta:g} c_h {ch:g} c_l {cl:g} Bij/E {bij:g}" + (f" anchor {anc[0]:g},{anc[1]:g}" if anc else "")
         + (f" cone {os.environ['CONE']}" if os.environ.get("CONE") else ""), lb.m, u, iters=its, force=F)
print("volume error %.1e" % lb.volume_error(u), f"{time.time() - t:.0f}s", flush=True)
