import numpy as np, time, sys
from vdmproto import *
p = Punch()
E = 3000
VA = None
kind = sys.argv[1]
rhos = [float(r) * 1e-3 for r in sys.argv[2].split(',')]
m0 = Model(p.X, p.T, p.fixed, 1, 1)
VA = m0.V0 / m0.Atot
for bij in [float(x) for x in sys.argv[4].split(',')]:
  for beta in [float(x) for x in sys.argv[3].split(',')]:
    terms = tuple((kind, 1.0 / r, r) for r in rhos)  # share x B: B = beta E (V/A), per-area beta E / rho_s
    m = Model(p.X, p.T, p.fixed, beta * E * VA, bij * E, bulk_terms=terms)
    u, it, F = p.run(m)
    p.report(f"{kind} rho {sys.argv[2]} beta {beta:g} Bij/E {bij:g}", m, u, force=F)
