import numpy as np, sys, time
from vdmproto import *
from dense_rigid import *
b = Beam(); E = 3000
m0 = Model(b.X, b.T, b.fixed, 1, 1); VA = m0.V0 / m0.Atot
cmax = float(sys.argv[1]); S = int(sys.argv[2]); beta = float(sys.argv[3]); bij = float(sys.argv[4])
kind = sys.argv[5] if len(sys.argv) > 5 else "rigid"
cases = sys.argv[6].split(',') if len(sys.argv) > 6 else ["stretch", "bend", "twist"]
rhos = [cmax * VA / 2 ** s for s in range(S)]
print("V/A", VA, "rhos mm", [round(r * 1e3, 1) for r in rhos], flush=True)
terms = tuple(("obj", beta * E * VA / r, DenseRigid(b.X, m0.area0, r, kind)) for r in rhos)
for case in cases:
    m = Model(b.X, b.T, b.fixed, 1.0, bij * E, bulk_terms=terms, corot=True)
    t = time.time(); u, it = b.run(m, case, it_max=150, anderson=10)
    print(f"{case:8s} c{cmax:g} S{S} beta {beta:g} Bij/E {bij:g} {kind}: A B C", b.errors(case, u).round(1), "it", it, f"{time.time()-t:.0f}s", flush=True)
