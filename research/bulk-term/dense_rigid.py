"""Linear (one-shot, rest geometry) solves with rigid-relative bulk terms of any radius:
dense kernel, matrix-free operator, GMRES preconditioned by the plain VDM system."""
import numpy as np, scipy.sparse as sp, scipy.sparse.linalg as spla
from vdmproto import *


class DenseRigid:
    def __init__(self, X, area, rho, kind="rigid", kernel="wendland"):
        d2 = ((X[:, None, :] - X[None, :, :]) ** 2).sum(-1) / rho ** 2
        Phi = np.where(d2 < 1, (1 - d2) ** 2, 0.0) * area[None, :]
        self.W = Phi / Phi.sum(1, keepdims=True)
        self.X, self.kind = X, kind
        self.c = self.W @ X
        WX2 = self.W @ (X ** 2).sum(1)
        WXX = np.einsum("ij,ja,jb->iab", self.W, X, X)
        c = self.c
        J = (WX2 - (c ** 2).sum(1))[:, None, None] * np.eye(3) - (WXX - np.einsum("ia,ib->iab", c, c))
        self.Jinv = np.linalg.pinv(J, rcond=1e-10)
        self.nb = (d2 < 1).sum(1).mean()

    def apply(self, u):
        mu = self.W @ u
        if self.kind == "mean": return mu
        mx = self.W @ np.cross(self.X, u)
        om = np.einsum("iab,ib->ia", self.Jinv, mx - np.cross(self.c, mu))
        return mu + np.cross(om, self.X - self.c)


def linear_solve(model, terms, mask, values, tol=1e-11):
    """terms: list of (Bs, DenseRigid). One linear solve at rest geometry; returns u, reaction."""
    n = model.n; X = model.X
    A = area_vectors(X, model.T)
    k = model.bulk_diag(A, X)
    diag = sum(Bs * k for Bs, _ in terms)
    K = sp.block_diag([model.L + sp.diags(diag[:, d]) for d in range(3)]).tocsr()
    C = (mask | model.fixed).T.ravel(); F = ~C
    vals = np.where(model.fixed, 0.0, values).T.ravel()
    a = A.T.ravel()
    KFF = K[F][:, F]
    M0 = sp.bmat([[KFF, -a[F][:, None]], [a[F][None, :], None]]).tocsc()
    lu = spla.splu(M0)
    nf = F.sum()

    def full(uF):
        v = vals.copy(); v[F] = uF; return v

    def bulk_load(v):  # sum_s Bs k (P_s u), axis-major 3n
        u = v.reshape(3, n).T
        f = np.zeros((n, 3))
        for Bs, P in terms: f += Bs * k * P.apply(u)
        return f.T.ravel()

    # system: K u - f(u) - dP a = 0 on F; a.u = 0 (c = V0 - V(X) + 0 = 0)
    def matvec(z):
        v = np.zeros(3 * n); v[F] = z[:-1]
        r = K[F][:, F] @ z[:-1] - bulk_load(v)[F] - a[F] * z[-1]
        return np.concatenate([r, [a[F] @ z[:-1]]])
    rhs0 = -(K[F][:, C] @ vals[C]) + bulk_load(vals * C)[F]
    rhs = np.concatenate([rhs0, [-(a[C] @ vals[C])]])
    Op = spla.LinearOperator((nf + 1, nf + 1), matvec=matvec)
    Pre = spla.LinearOperator((nf + 1, nf + 1), matvec=lu.solve)
    z, info = spla.gmres(Op, rhs, M=Pre, tol=tol, restart=200, maxiter=50)
    v = full(z[:-1])
    u = v.reshape(3, n).T
    reaction = (K @ v - bulk_load(v) - z[-1] * a).reshape(3, n).T
    return u, reaction, info


def kabsch_reference(self, x):
    X, W, c = self.X, self.W, self.c
    cp = W @ x
    S = np.einsum("ij,ja,jb->iab", W, x, X) - np.einsum("ia,ib->iab", cp, c)
    if self.kind == "mean": return cp - X
    U, s, Vt = np.linalg.svd(S)
    det = np.sign(np.linalg.det(U @ Vt))
    U[:, :, 2] *= det[:, None]
    R = U @ Vt
    return cp + np.einsum("iab,ib->ia", R, X - c) - X
DenseRigid.reference = kabsch_reference
