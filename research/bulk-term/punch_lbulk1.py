"""The flat punch with lbulk.py, 1 mm in ONE step iterated to convergence (geometry, the
capsule's and the aux fields' rotations; Anderson). Usage: punch_lbulk1.py form beta_a [c_a]"""
import numpy as np, sys, time, os
from lbulk import *
p = Punch(); h = np.loadtxt(D + "punch_thickness.txt")
form = sys.argv[1]; ba = float(sys.argv[2]); ca = float(sys.argv[3]) if len(sys.argv) > 3 else 1.5
n = len(p.X); mask = np.zeros((n, 3), bool); mask[p.moved] = True
cn = (mask | p.fixed).all(1).astype(float)
t = time.time()
lb = LBulk(p.X, p.T, p.fixed, h, beta=0.3, c_h=0.5, c_l=1, bij=0.01, corot=form.startswith("corot"),
           aux_corot={"corot": True, "corot-scale": "scale", "corot-thick": "thick"}.get(form, False), anchor=(ba, ca, cn))
vals = np.zeros((n, 3)); vals[p.moved, 2] = -0.001
u, it, du = lb.solve(np.zeros((n, 3)), mask, vals, it_max=40, tol=1e-9, anderson=6)
p.report(f"{form} C_R {os.environ.get('C_R', '1')} anchor {ba:g},{ca:g} (1 step)", lb.m, u, iters=it, force=-lb.reaction[p.moved, 2].sum())
print("   last du %.1e volume error %.1e" % (du, lb.volume_error(u)), f"{time.time() - t:.0f}s", flush=True)
