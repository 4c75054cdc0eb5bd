"""Beams with the local-thickness aux-field bulk (lbulk.py), corotational or membrane capsule,
optionally with lanchor.py's boundary anchor.
Usage: beam_lbulk.py beta c_h Bij/E c_l corot|membrane cases [beta_a,c_a]"""
import numpy as np, sys, time, os
from lbulk import *
b = Beam(); h = np.loadtxt(D + b.name + "_thickness.txt")
beta, ch, bij, cl = (float(x) for x in sys.argv[1:5])
form = sys.argv[5]; cases = sys.argv[6].split(",")
anc = [float(x) for x in sys.argv[7].split(",")] if len(sys.argv) > 7 else None
for case in cases:
    moved, targets = b.cases[case]
    n = len(b.X); mask = np.zeros((n, 3), bool); mask[moved] = True
    cn = (mask | b.fixed).all(1).astype(float)
    lb = LBulk(b.X, b.T, b.fixed, h, beta=beta, c_h=ch, c_l=cl, bij=bij, corot=(form in ("corot", "corot-skin", "corot-scale", "corot-thick")), aux_corot={"corot": True, "corot-scale": "scale", "corot-thick": "thick"}.get(form, False),
               anchor=(anc[0], anc[1], cn) if anc else None)
    if case == cases[0]: print(lb.stats(), flush=True)
    t = time.time()
    u, its, du = run_beam(b, lb, case, steps=5)
    print(f"{b.name} {case:8s} {form} aux beta {beta:g} c_h {ch:g} c_l {cl:g} Bij/E {bij:g}" + (f" anchor {anc[0]:g},{anc[1]:g}" if anc else "") + (f" cone {os.environ['CONE']}" if os.environ.get("CONE") else "") + (" rigid-anchor" if os.environ.get("RIGID_ANCHOR") == "1" else "") + ": A B C",
          b.errors(case, u).round(1), "it", its, "last du %.1e" % du, "vol err %.1e" % lb.volume_error(u), f"{time.time() - t:.0f}s", flush=True)
