#!/usr/bin/python3
"""How stiff the sloshing cases' rubber plate is in 3D, against the 2D planes.

The 2D plate of cases/sloshing_* bends in plane stress (the cases) or plane
strain. The real plate is a strip 4 mm thick and 39 mm broad (the tank's
breadth) with free side edges, clamped across its breadth in the floor. Near
the clamp its cross-section is held flat (plane strain); away from it the
strip may curl anticlastically (plane stress) unless it bends so far that
the curl costs membrane energy (Ashwell 1950). This script settles where
between the planes that strip lies, with a 3D finite-element model of it:
27-node hexahedra, total Lagrangian, St Venant-Kirchhoff (the strains stay
below about 5%; the rotations are large), Newton on load steps.

Three 3D bodies, same mesh along the plate, same load:
  real    half the breadth (19.5 mm) with a symmetry plane, free edge
  strain  u_z = 0 everywhere: exactly plane strain
  stress  a strip 0.25 mm broad: its cross-section curls freely (sigma_zz ~ 0)
Load: a uniform dead pressure on one face (a first-mode sloshing load is
spread over the plate; a follower load would turn with the face, the same
for the three bodies). The plate's stiffness factor against plane stress is
f = q_body(delta) / q_stress(delta), the load that bends it to the same tip
deflection delta: 1 in plane stress, about 1 / (1 - nu^2) = 1.316 in plane
strain. It is reported at small deflection (linear) and at the experiment's
crest for each filling.

  bench/plate_3d_stiffness.py                 # both fillings, the table
  bench/plate_3d_stiffness.py --mesh 2 4 40   # through-thickness, half-breadth, length elements
"""
import argparse
import sys
import time

import numpy as np

import plate_fe  # the 1-D quadratic shape functions and the Gauss rule of the 2D reference

try:  # scipy's sparse LU where it is there; numpy's dense solve (as on CI) otherwise
    import scipy.sparse as sp
    import scipy.sparse.linalg as spla
    SPARSE = True
except ImportError:
    SPARSE = False

E_RUBBER = 6.0e6     # Pa, the cases' (paper 5.4)
NU_RUBBER = 0.49
THICK = 0.004        # m
BREADTH = 0.039      # m, the tank's breadth (docs/sloshing.md, "Side walls")
# (length, the experiment's crest amplitude): tip_dx +7.38 / -7.52 cm at the
# high filling; the low one's 1.44 cm peak to peak
FILLINGS = {'high': (0.1148, 0.0745), 'low': (0.0574, 0.0072)}

def hex27_tables():
    """Shape-function derivatives (gp, 27, 3) in the reference cube and the
    weights (gp): the tensor product of plate_fe's 1-D quadratics, local node
    9 i + 3 j + l for (x, y, z) indices (i, j, l)."""
    n, d = plate_fe.lagrange2(plate_fe.GAUSS_X)           # (gp, node)
    dN = np.stack([np.einsum('ai,bj,cl->abcijl', d, n, n),
                   np.einsum('ai,bj,cl->abcijl', n, d, n),
                   np.einsum('ai,bj,cl->abcijl', n, n, d)], axis=-1).reshape(27, 27, 3)
    W = plate_fe.GAUSS_W
    return dN, np.einsum('a,b,c->abc', W, W, W).ravel()


def quad9_tables():
    """Face shape functions (gp, 9) and weights on the reference square."""
    n, _ = plate_fe.lagrange2(plate_fe.GAUSS_X)
    return (np.einsum('ai,bj->abij', n, n).reshape(9, 9),
            np.outer(plate_fe.GAUSS_W, plate_fe.GAUSS_W).ravel())


class Plate:
    """A box [0, t] x [0, L] x [0, b] of 27-node hexahedra; x through the
    thickness, y along the plate (clamped at y = 0), z across the breadth
    (z = 0 a symmetry plane or, for 'strain', u_z = 0 everywhere)."""

    def __init__(self, length, breadth, ne, kind, E=E_RUBBER, nu=NU_RUBBER, thick=THICK):
        self.kind = kind
        nx, nz, ny = ne
        xs = np.linspace(0.0, thick, 2 * nx + 1)
        ys = np.linspace(0.0, length, 2 * ny + 1)
        zs = np.linspace(0.0, breadth, 2 * nz + 1)
        X, Y, Z = np.meshgrid(xs, ys, zs, indexing='ij')
        self.X = np.stack([X.ravel(), Y.ravel(), Z.ravel()], axis=1)
        idx = np.arange(self.X.shape[0]).reshape(len(xs), len(ys), len(zs))
        conn = []
        for i in range(nx):
            for j in range(ny):
                for k in range(nz):
                    conn.append(idx[2 * i:2 * i + 3, 2 * j:2 * j + 3, 2 * k:2 * k + 3].ravel())
        self.conn = np.array(conn)
        # the loaded face x = 0: its 9-node patches
        face = []
        for j in range(ny):
            for k in range(nz):
                face.append(idx[0, 2 * j:2 * j + 3, 2 * k:2 * k + 3].ravel())
        self.face = np.array(face)
        self.ndof = 3 * self.X.shape[0]
        fixed = np.zeros((self.X.shape[0], 3), bool)
        fixed[self.X[:, 1] == 0.0, :] = True              # the clamp
        fixed[self.X[:, 2] == 0.0, 2] = True              # symmetry plane
        if kind == 'strain':
            fixed[:, 2] = True
        self.free = np.flatnonzero(~fixed.ravel())
        # the tip's centreline: mid-thickness, the symmetry plane, top
        self.tip = int(idx[nx, -1, 0])
        dN, self.w = hex27_tables()
        Xe = self.X[self.conn]                           # (ne, 27, 3)
        J = np.einsum('eai,gaj->egij', Xe, dN)           # dX/dxi
        self.detJ = np.linalg.det(J)
        self.dNdX = np.einsum('gaj,egji->egai', dN, np.linalg.inv(J))
        self.lam, self.mu = E * nu / ((1 + nu) * (1 - 2 * nu)), E / (2 * (1 + nu))
        rows = np.repeat(3 * self.conn[:, :, None] + np.arange(3), 1, axis=2).reshape(len(conn), 81)
        self.rows = np.repeat(rows[:, :, None], 81, axis=2).ravel()
        self.cols = np.repeat(rows[:, None, :], 81, axis=1).ravel()
        self.edofs = rows
        # the unit pressure's nodal forces (+x on the face x = 0, dead load)
        Nf, wf = quad9_tables()
        self.fext = np.zeros(self.ndof)
        dy = length / ny / 2.0
        dz = breadth / nz / 2.0
        for nodes in self.face:
            fn = (Nf * wf[:, None]).sum(axis=0) * dy * dz
            np.add.at(self.fext, 3 * nodes, fn)

    def residual_tangent(self, u):
        ue = u[self.edofs].reshape(-1, 27, 3)
        F = np.eye(3) + np.einsum('eai,egaj->egij', ue, self.dNdX)
        Eg = 0.5 * (np.einsum('egki,egkj->egij', F, F) - np.eye(3))
        trE = np.trace(Eg, axis1=2, axis2=3)
        S = self.lam * trE[..., None, None] * np.eye(3) + 2 * self.mu * Eg
        P = np.einsum('egik,egkj->egij', F, S)
        wdet = self.detJ * self.w                        # (ne, gp)
        fint_e = np.einsum('egij,egaj,eg->eai', P, self.dNdX, wdet).reshape(-1, 81)
        fint = np.bincount(self.edofs.ravel(), fint_e.ravel(), minlength=self.ndof)
        # A_iJkL = d_ik S_JL + lam F_iJ F_kL + mu F_iL F_kJ + mu (F F^T)_ik d_JL,
        # each term a sum over the Gauss points written as one batched matrix
        # product per element (einsum's generic loop over five indices took
        # three quarters of the model's time)
        B = self.dNdX
        ne, ng = wdet.shape
        Bw, Bt = B * wdet[..., None, None], np.swapaxes(B, 2, 3)
        FB = np.matmul(B, np.swapaxes(F, 2, 3))          # F_iJ dN_a/dX_J: (e, g, a, i)
        BBw = np.matmul(Bw, Bt)
        geo = np.matmul(np.matmul(Bw, S), Bt)
        FFt = np.matmul(F, np.swapaxes(F, 2, 3))
        FBw = (FB * wdet[..., None, None]).reshape(ne, ng, 81)
        FBr = FB.reshape(ne, ng, 81)
        # sum_g FBw[g, (a, i)] FB[g, (b, k)]: the lam term as it stands; the mu
        # term is its (a, k) (b, i) rearrangement
        G = np.matmul(np.swapaxes(FBw, 1, 2), FBr).reshape(ne, 27, 3, 27, 3)
        # sum_g BBw[g, (a, b)] FFt[g, (i, k)]
        H = np.matmul(np.swapaxes(BBw.reshape(ne, ng, 729), 1, 2),
                      FFt.reshape(ne, ng, 9)).reshape(ne, 27, 27, 3, 3)
        I3 = np.eye(3)
        Ke = (geo.sum(axis=1)[:, :, None, :, None] * I3[None, None, :, None, :]
              + self.lam * G
              + self.mu * G.transpose(0, 1, 4, 3, 2)
              + self.mu * H.transpose(0, 1, 3, 2, 4)).reshape(-1, 81 * 81)
        return fint, Ke

    def _solve_free(self, Ke, rf):
        """The tangent's free block, assembled from the element blocks Ke, solved for rf."""
        if SPARSE:
            K = sp.csr_matrix((Ke.ravel(), (self.rows, self.cols)), shape=(self.ndof, self.ndof))
            return spla.spsolve(K[self.free][:, self.free].tocsc(), rf)
        K = np.bincount(self.rows * self.ndof + self.cols, Ke.ravel(),
                        minlength=self.ndof * self.ndof).reshape(self.ndof, self.ndof)
        return np.linalg.solve(K[np.ix_(self.free, self.free)], rf)

    def solve(self, q, u0=None, steps=1):
        """Static equilibrium under pressure q (Pa), from u0 in load steps."""
        u = np.zeros(self.ndof) if u0 is None else u0.copy()
        if u0 is None:
            self.path = [(0.0, 0.0)]   # (load, tip) at each load step from rest
        q0 = 0.0 if u0 is None else self._q
        for s in range(1, steps + 1):
            ql = q0 + (q - q0) * s / steps
            for it in range(40):
                fint, Ke = self.residual_tangent(u)
                r = ql * self.fext - fint
                rf = r[self.free]
                if it > 0 and np.linalg.norm(rf) <= 1e-8 * np.linalg.norm(ql * self.fext[self.free]):
                    break
                du = self._solve_free(Ke, rf)
                u[self.free] += du
                if np.linalg.norm(du) <= 1e-10 * np.linalg.norm(u):
                    break
            else:
                raise RuntimeError(f'{self.kind}: Newton did not converge at q = {ql:.3g} Pa')
            self.path.append((ql, self.tip_dx(u)))
        self._q = q
        return u

    def tip_dx(self, u):
        return u[3 * self.tip]


def load_for(plate, delta, q_guess):
    """The pressure that bends the plate's tip by delta (secant on q)."""
    u = None
    q = q_guess
    u = plate.solve(q, None, steps=max(1, int(delta / 0.01)))
    d = plate.tip_dx(u)
    qa, da = 0.0, 0.0
    for _ in range(30):
        if abs(d - delta) < 1e-5 * delta or d == da:
            return q, u
        qn = q + (delta - d) * (q - qa) / (d - da)
        qa, da = q, d
        q = qn
        u = plate.solve(q, u, steps=2)
        d = plate.tip_dx(u)
    raise RuntimeError(f'{plate.kind}: no load found for a tip of {delta} m')


STRIP = 0.25e-3   # m: the 'stress' body's breadth, a sixteenth of the thickness


def stiffness_factors(length, crest, mesh, small=1e-4, linear_only=False,
                      bodies=('stress', 'real', 'strain'), energy=True):
    """{body: (q at the small tip, q at the crest, k of a swing to the crest,
    wall s)} and the factors {body: (f small, f crest, f swing)} against the
    'stress' body (which bodies must hold); mesh (nt, nb, nl). f crest
    compares the loads that hold the tip at the crest (secant stiffness),
    f swing the describing functions of a harmonic swing to the crest (the
    linear stiffness with the same first harmonic: for a cubic spring
    k1 + 3/4 k3 A^2, three quarters of the way from the small tip's to the
    secant's). linear_only: the crest is not solved (None); energy=False: nor
    the swing (None)."""
    res = {}
    for kind in bodies:
        t0 = time.time()
        nb = 1 if kind == 'stress' else mesh[1]
        breadth = STRIP if kind == 'stress' else BREADTH / 2
        plate = Plate(length, breadth, (mesh[0], nb, mesh[2]), kind)
        # Euler-Bernoulli in plane stress for a first guess: q L^4 / (8 E I)
        qg = lambda d: d * 8 * E_RUBBER * THICK ** 3 / 12 / length ** 4
        ql, _ = load_for(plate, small, qg(small))
        qc = wc = None
        if not linear_only:
            qc = load_for(plate, crest, qg(crest))[0]
        if not linear_only and energy:
            # the load path from rest to the crest's load, in 16 steps
            plate.solve(qc, None, steps=16)
            q, d = np.array(plate.path).T
            # the describing function: the first harmonic of the load over a
            # swing A cos(theta) (the plate's swing is close to a sinusoid),
            # k = (4 / (pi A)) int_0^(pi/2) q(A cos theta) cos theta dtheta
            th = np.linspace(0.0, np.pi / 2, 401)
            g = np.interp(d[-1] * np.cos(th), d, q) * np.cos(th)
            wc = float(4.0 / (np.pi * d[-1]) * np.sum(0.5 * (g[1:] + g[:-1]) * np.diff(th)))
        res[kind] = (ql, qc, wc, time.time() - t0)
    s = res['stress']
    f = {k: (v[0] / s[0], None if qc is None else v[1] / s[1],
             None if wc is None else v[2] / s[2]) for k, v in res.items()}
    return res, f


def main():
    ap = argparse.ArgumentParser(description=__doc__.split('\n')[0])
    ap.add_argument('--mesh', type=int, nargs=3, default=[2, 4, 0],
                    metavar=('NT', 'NB', 'NL'),
                    help='elements through the thickness, across the half breadth, '
                         'along the plate (0: about 2.9 mm long)')
    ap.add_argument('--fillings', nargs='+', default=['high', 'low'], choices=FILLINGS)
    ap.add_argument('--small', type=float, default=1e-4,
                    help='the "linear" tip deflection, m')
    args = ap.parse_args()
    print('| filling | body | mesh (t, b/2, L) | f at a tip of %.2g mm (linear) | crest '
          '| f there (secant) | f of a swing to the crest (describing function) | wall s |'
          % (args.small * 1e3))
    print('|---|---|---|---|---|---|---|---|')
    for name in args.fillings:
        length, crest = FILLINGS[name]
        nl = args.mesh[2] or int(round(length / 0.0029))
        res, f = stiffness_factors(length, crest, (args.mesh[0], args.mesh[1], nl), args.small)
        for kind in ('stress', 'real', 'strain'):
            nb = 1 if kind == 'stress' else args.mesh[1]
            print(f'| {name} | {kind} | {args.mesh[0]}, {nb}, {nl} | {f[kind][0]:.3f} '
                  f'| {crest * 100:.2f} cm | {f[kind][1]:.3f} | {f[kind][2]:.3f} '
                  f'| {res[kind][3]:.0f} |', flush=True)
        eb = args.small * 8 * E_RUBBER * THICK ** 3 / 12 / length ** 4
        print(f'{name}: the stress body takes {res["stress"][0]:.4g} Pa for the small tip, '
              f'Euler-Bernoulli {eb:.4g} Pa', file=sys.stderr)
    return 0


if __name__ == '__main__':
    sys.exit(main())
