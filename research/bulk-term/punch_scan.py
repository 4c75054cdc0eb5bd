import numpy as np, time, sys
from vdmproto import *
p = Punch()
B, Bij = 0.0892 * 3000, 0.2535 * 3000
kind = sys.argv[1]
for rho in [float(r) for r in sys.argv[2].split(',')]:
    for bm in [float(r) for r in sys.argv[3].split(',')]:
        t = time.time()
        m = Model(p.X, p.T, p.fixed, B * bm, Bij, bulk_terms=((kind, 1.0, rho),))
        nnz = m.terms[0][2].nnz_per_row
        u, it, F = p.run(m)
        p.report(f"{kind} rho {rho*1e3:.0f}mm B x{bm:g} nb {nnz:.0f}", m, u, force=F)
