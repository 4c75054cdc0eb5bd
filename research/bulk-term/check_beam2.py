import numpy as np, time
from vdmproto import *
b = Beam()
B, Bij = 0.0892 * 3000, 0.2535 * 3000
for case in ("stretch", "bend", "twist"):
    for tag, Bx in (("corotational_skin", 1e-4 * Bij), ("corotational", B)):
        ref = np.loadtxt(D + f"beam_{case}_vdm_{tag}_u.txt")
        m = Model(b.X, b.T, b.fixed, Bx, Bij, corot=True)
        t = time.time(); u, it = b.run(m, case, it_max=100, anderson=8)
        print(case, tag, "proto", b.errors(case, u).round(1), "engine", b.errors(case, ref).round(1), "max diff %.2e" % np.abs(u-ref).max(), "it", it, f"{time.time()-t:.1f}s", flush=True)
