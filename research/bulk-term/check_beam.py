import numpy as np, time
from vdmproto import *
b = Beam()
B, Bij = 0.0892 * 3000, 0.2535 * 3000
for case in ("stretch", "bend", "twist"):
    ref = np.loadtxt(D + f"beam_{case}_vdm_membrane_u.txt")
    m = Model(b.X, b.T, b.fixed, B, Bij)
    t = time.time(); u, it = b.run(m, case, it_max=1, anderson=0)
    print(case, "membrane proto", b.errors(case, u).round(1), "engine", b.errors(case, ref).round(1), "max diff", np.abs(u-ref).max(), f"{time.time()-t:.1f}s")
