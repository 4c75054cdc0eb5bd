import numpy as np, time
from vdmproto import *
p = Punch()
B, Bij = 0.0892 * 3000, 0.2535 * 3000
m = Model(p.X, p.T, p.fixed, B, Bij)
t = time.time(); u, it, F = p.run(m)
p.report("membrane (paper bulk)", m, u, force=F)
ref = np.loadtxt(D + "punch_vdm_membrane_u.txt"); p.report("engine membrane", m, ref)
print(time.time() - t)
