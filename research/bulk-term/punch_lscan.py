"""Scan of the local-thickness bulk's constants on the flat punch (one linear step at rest geometry)."""
import numpy as np, sys, itertools, os
from lbulk import *
p = Punch(); h = np.loadtxt(D + "punch_thickness.txt")
betas = [float(x) for x in sys.argv[1].split(",")]
chs = [float(x) for x in sys.argv[2].split(",")]
bijs = [float(x) for x in sys.argv[3].split(",")]
cl = float(sys.argv[4]) if len(sys.argv) > 4 else 1.0
anc = [float(x) for x in sys.argv[5].split(",")] if len(sys.argv) > 5 else None   # beta_a,c_a
n = len(p.X); mask = np.zeros((n, 3), bool); mask[p.moved] = True
cn = (mask | p.fixed).all(1).astype(float)
for bij, ch, beta in itertools.product(bijs, chs, betas):
    lb = LBulk(p.X, p.T, p.fixed, h, beta=beta, c_h=ch, c_l=cl, bij=bij, corot=False,
               anchor=(anc[0], anc[1], cn) if anc else None)
    u, its, F = run_punch(p, lb, steps=1, it_max=1)
    d, rel = p.report(f"beta {beta:g} c_h {ch:g} c_l {cl:g} Bij/E {bij:g} S{lb.S}" + (f" anchor {anc[0]:g},{anc[1]:g}" if anc else "") + (f" cone {os.environ['CONE']}" if os.environ.get("CONE") else ""), lb.m, u, force=F)
