#!/usr/bin/python3
"""A converged 2-D finite-element reference for the plate at rest
(cases/hard_plate_at_rest): the tip deflection of the continuum problem that
bench/hard_cases.py rest_analytic() approximates as an Euler-Bernoulli beam.

usage: bench/plate_fe.py [--dp DP ...] [--no-weight] [--nonlinear | --follower]
                         [--both] [--dense] [--fixed-volume] [--validate] [--max-nx N]

  --dp         particle spacings (m): they set the water levels h - dp/2 and
               the probe point (default 0.003 0.0015 0.001 0.00075)
  --no-weight  no self-weight (lateral water load alone)
  --nonlinear  the geometrically nonlinear solution (dead loads) in place of
               the linearised one
  --follower   nonlinear, with the water pressure at the current faces
  --both       with and without weight: linearised, nonlinear, follower
  --dense      numpy dense solves even where scipy is there (as on CI)
  --fixed-volume  the basins are closed: the bent plate lowers the left level
               by the room it gives that basin (its width 0.294 m) and raises
               the right one (0.278 m), iterated; the particle runs hold
               volumes, not levels, so this is what they should approach
  --validate   the FE's own checks: a slender cantilever against
               Euler-Bernoulli + Timoshenko shear, the self-weight buckling load
  --max-nx     the finest mesh of the sequence 2, 4, 8, ... (default 16 with
               scipy, 8 without)

The problem (SI units, per metre of depth). The plate is the rectangle
x in [0, b], y in [0, L] (b = 12 mm, L = 84 mm), linear elastic, plane
strain (E = 1 MPa, nu = 0 by default: then plane stress is the same),
clamped on y = 0 (u = v = 0). Still water pushes on both faces: on x = 0,
t_x = +rho_w g (h1 - y) below h1; on x = b, t_x = -rho_w g (h2 - y) below h2,
with the "effective" levels h = 72 mm - dp/2 and 24 mm - dp/2 (the fluid
puts P = 0 at its top particles' centres; rest_levels in hard_cases.py). The
loads are dead loads (fixed direction, at the undeformed positions).
The own weight, the body force (0, -rho_s g), bends the soft upright plate
further (P-delta). The linearised solution takes it in through the
initial-stress matrix: solve K u0 = f_weight for the vertical compression
sigma0, then (K + K_G(sigma0)) u = f_lateral + f_weight, K_G = int grad(N)^T
sigma0 grad(N) for each displacement component: the consistent linearisation
about the straight plate, what the beam-column formula of rest_analytic does.
The nonlinear solution (total Lagrangian, St Venant-Kirchhoff, Newton, the
load in increments) checks that linearisation.

Elements: 9-node biquadratic Lagrange quads, 3x3 Gauss points (no shear
locking in bending), a uniform mesh of nx x ny elements, ny = 7 nx. The
output is u_x at the probe of the particle runs, (dp/2, L - dp/2) (tip_dx
sits at the top upstream particle's centre), interpolated with the element's
shape functions, and u_x at (b/2, L). converged() runs nx = 2, 4, 8 (and 16)
and Richardson-extrapolates: the observed order is about 3 (with nu = 0 the
bending field fits the clamp, so its corners' singularity is weak) and nx = 8
is already within 1e-5 of the limit.

What it found (dp = 0.75 mm, u_x at the probe against rest_analytic's
Euler-Bernoulli): linearised +2.7% with weight, +2.2% without (shear, the
2-D root). The nonlinear solution under dead loads is 2.0-2.5% above the
linearised one, not well under 1%: a horizontal dead load on a face stays on
its material point, b/2 off the axis, which rises (tension face) or sinks
(compression face) by theta b/2 as the section turns, lengthening its lever
arm, a first-order effect in theta b / (2 lever) that beam theory puts at
+1.9%. bench/solid_static_load.c loads the MPS plate in that same way (fixed
horizontal forces on the outer particle columns), so its deflections compare
with the nonlinear dead-load figures (+5.5% / +4.5%). Real water pushes normal
to the deformed faces (the lever effect cancels) at the current heights (the
risen face feels less pressure): --follower gives +1.75% / +1.0%, the
reference for the coupled runs.
"""
import argparse
import json
import math
import sys
import time

import numpy as np

try:  # scipy is on developers' machines, not on CI: numpy dense without it
    import scipy.sparse as sps
    import scipy.sparse.linalg as spla
except ImportError:
    sps = None

SPARSE = sps is not None   # a caller (the ctest) may set False to run as on CI

RHO_W, G = 1000.0, 9.81
# The plate of cases/hard_plate_at_rest (hard_cases.py REST), clamped at y = 0.
PLATE = dict(b=0.012, L=0.084, E=1.0e6, rho_s=2500.0, h1=0.072, h2=0.024)
# The widths of the two closed basins (the tank is 0.584 m wide, the plate's
# faces at x = 0.294 and 0.306): what --fixed-volume divides the room the bent
# plate gives or takes by.
BASINS = dict(w1=0.294, w2=0.584 - 0.306)


# ---------------------------------------------------------------- the Q9 element

GAUSS_X = np.array([-math.sqrt(0.6), 0.0, math.sqrt(0.6)])
GAUSS_W = np.array([5.0, 8.0, 5.0]) / 9.0


def lagrange2(t):
    """1-D quadratic Lagrange shape functions on [-1, 1] (nodes -1, 0, 1) and
    their derivatives, at the points t: two arrays (len(t), 3)."""
    t = np.asarray(t, float)[:, None]
    n = np.hstack([t * (t - 1) / 2, 1 - t * t, t * (t + 1) / 2])
    d = np.hstack([t - 0.5, -2 * t, t + 0.5])
    return n, d


def q9_at(xi, eta):
    """Q9 shape functions (tensor product, local node a = ix + 3 iy) and their
    reference derivatives at the points (xi, eta): (n, 9) and (n, 9, 2)."""
    nx, dx = lagrange2(xi)
    ny, dy = lagrange2(eta)
    N = (ny[:, :, None] * nx[:, None, :]).reshape(-1, 9)
    dN = np.stack([(ny[:, :, None] * dx[:, None, :]).reshape(-1, 9),
                   (dy[:, :, None] * nx[:, None, :]).reshape(-1, 9)], axis=-1)
    return N, dN


class Mesh:
    """A uniform nx x ny mesh of Q9 elements on [0, b] x [0, L]. Nodes are
    numbered row by row (x fastest); dof 2 k + i is component i of node k.
    The elements are equal rectangles, so the Jacobian is one constant."""

    def __init__(self, nx, ny, b, L):
        self.nx, self.ny, self.b, self.L = nx, ny, b, L
        self.hx, self.hy = b / nx, L / ny
        self.cols, self.rows = 2 * nx + 1, 2 * ny + 1
        self.nnode = self.cols * self.rows
        self.ndof = 2 * self.nnode
        ex, ey = np.meshgrid(np.arange(nx), np.arange(ny))
        ex, ey = ex.ravel(), ey.ravel()          # element e = ex + nx ey
        a = np.arange(9)
        self.conn = (2 * ey[:, None] + a // 3) * self.cols + 2 * ex[:, None] + a % 3
        self.dofs = (2 * self.conn[:, :, None] + np.arange(2)).reshape(-1, 18)
        gx, gy = np.meshgrid(GAUSS_X, GAUSS_X)
        N, dN = q9_at(gx.ravel(), gy.ravel())
        self.N = N                                           # (9 gp, 9 nodes)
        self.dN = dN * np.array([2 / self.hx, 2 / self.hy])  # d/dx, d/dy
        self.wdet = np.outer(GAUSS_W, GAUSS_W).ravel() * self.hx * self.hy / 4
        clamped = np.arange(self.cols)                       # the row y = 0
        fixed = np.concatenate([2 * clamped, 2 * clamped + 1])
        self.free = np.setdiff1d(np.arange(self.ndof), fixed)

    def node_xy(self, k):
        return (k % self.cols) * self.hx / 2, (k // self.cols) * self.hy / 2

    def interp(self, u, x, y):
        """(u_x, u_y) at the point (x, y), with the element's shape functions."""
        ex = min(int(x / self.hx), self.nx - 1)
        ey = min(int(y / self.hy), self.ny - 1)
        xi = 2 * (x - ex * self.hx) / self.hx - 1
        eta = 2 * (y - ey * self.hy) / self.hy - 1
        N, _ = q9_at([xi], [eta])
        ue = u[self.dofs[ex + self.nx * ey]].reshape(9, 2)
        return N[0] @ ue


# ---------------------------------------------------------------- material

def elasticity(E, nu):
    """The plane-strain elasticity tensor C_IJKL (2x2x2x2)."""
    lam = E * nu / ((1 + nu) * (1 - 2 * nu))
    mu = E / (2 * (1 + nu))
    d = np.eye(2)
    return (lam * np.einsum('ij,kl->ijkl', d, d)
            + mu * (np.einsum('ik,jl->ijkl', d, d) + np.einsum('il,jk->ijkl', d, d)))


def gradients(mesh, u):
    """grad u at every Gauss point: (nel, 9 gp, 2 (i), 2 (J)), du_i/dX_J."""
    ue = u[mesh.dofs].reshape(-1, 9, 2)
    return np.einsum('eai,gaJ->egiJ', ue, mesh.dN)


def lin_stress(mesh, u, C):
    """Small-strain stress at the Gauss points (nel, 9, 2, 2)."""
    H = gradients(mesh, u)
    return np.einsum('IJKL,egKL->egIJ', C, 0.5 * (H + H.transpose(0, 1, 3, 2)))


# ---------------------------------------------------------------- assembly

def element_matrices(mesh, A):
    """Element matrices K_e[a i, b m] = int dN_a/dX_J A_iJmL dN_b/dX_L, for a
    tangent A given per element and Gauss point (nel, 9, 2, 2, 2, 2) or the
    same for all (9, 2, 2, 2, 2): (nel or 1, 18, 18)."""
    A = A if A.ndim == 6 else A[None]
    Ke = np.einsum('g,gaJ,egiJmL,gbL->eaibm', mesh.wdet, mesh.dN, A, mesh.dN, optimize=True)
    return Ke.reshape(len(A), 18, 18)


def assemble(mesh, Ke):
    """The global matrix: scipy CSR when SPARSE, else a dense numpy array.
    One Ke (1, 18, 18) stands for every element."""
    nel = len(mesh.dofs)
    Ke = np.broadcast_to(Ke, (nel, 18, 18))
    r = np.broadcast_to(mesh.dofs[:, :, None], Ke.shape).ravel()
    c = np.broadcast_to(mesh.dofs[:, None, :], Ke.shape).ravel()
    n = mesh.ndof
    if SPARSE:
        return sps.csr_matrix((Ke.ravel(), (r, c)), shape=(n, n))
    return np.bincount(r * n + c, weights=Ke.ravel(), minlength=n * n).reshape(n, n)


def assemble_vector(mesh, fe):
    """The global vector from element vectors (nel, 18)."""
    return np.bincount(mesh.dofs.ravel(), weights=fe.ravel(), minlength=mesh.ndof)


def solve_free(mesh, K, f):
    """Solves K u = f on the free dofs (the clamped row is u = v = 0)."""
    fr = mesh.free
    u = np.zeros(mesh.ndof)
    if SPARSE:
        u[fr] = spla.spsolve(K[fr][:, fr].tocsc(), f[fr])
    else:
        u[fr] = np.linalg.solve(K[np.ix_(fr, fr)], f[fr])
    return u


def stiffness(mesh, C):
    """The small-strain stiffness: the tangent A = C for every element."""
    return assemble(mesh, element_matrices(mesh, np.broadcast_to(C, (9, 2, 2, 2, 2))))


def geometric_stiffness(mesh, sigma):
    """The initial-stress matrix int dN_a/dX_J sigma_JL dN_b/dX_L, the same for
    each displacement component (A_iJmL = delta_im sigma_JL)."""
    A = np.einsum('im,egJL->egiJmL', np.eye(2), sigma)
    return assemble(mesh, element_matrices(mesh, A))


# ---------------------------------------------------------------- loads

def edge_load(mesh, side, traction, breaks=()):
    """Consistent nodal forces of a horizontal traction t_x(y) (N/m^2) on the
    face x = 0 (side 0) or x = b (side 1). traction is piecewise linear, with
    its kinks at breaks: each element edge is split there and integrated with
    3 Gauss points (exact for a quadratic shape function times a linear load)."""
    f = np.zeros(mesh.ndof)
    col = 0 if side == 0 else mesh.cols - 1
    for j in range(mesh.ny):
        y0, y1 = j * mesh.hy, (j + 1) * mesh.hy
        cuts = [y0] + sorted(y for y in breaks if y0 < y < y1) + [y1]
        for a, c in zip(cuts[:-1], cuts[1:]):
            y = 0.5 * (a + c) + 0.5 * (c - a) * GAUSS_X
            N, _ = lagrange2(2 * (y - y0) / mesh.hy - 1)
            fn = (N * (traction(y) * GAUSS_W * 0.5 * (c - a))[:, None]).sum(axis=0)
            nodes = (2 * j + np.arange(3)) * mesh.cols + col
            f[2 * nodes] += fn
    return f


def water_load(mesh, h1, h2):
    """Still water on both faces: +rho_w g (h1 - y) on x = 0 below h1,
    -rho_w g (h2 - y) on x = b below h2."""
    left = edge_load(mesh, 0, lambda y: RHO_W * G * np.clip(h1 - y, 0, None), [h1])
    right = edge_load(mesh, 1, lambda y: -RHO_W * G * np.clip(h2 - y, 0, None), [h2])
    return left + right


def weight_load(mesh, rho_s):
    """The body force (0, -rho_s g) per unit reference area."""
    fe = np.zeros((len(mesh.dofs), 9, 2))
    fe[:, :, 1] = -rho_s * G * (mesh.wdet @ mesh.N)
    return assemble_vector(mesh, fe)


# ---------------------------------------------------------------- solutions

def linearised(mesh, C, f_lateral, f_weight=None):
    """Linear elasticity; with f_weight, about the plate prestressed by its
    weight: u0 from K u0 = f_weight gives sigma0, then
    (K + K_G(sigma0)) u = f_lateral + f_weight."""
    K = stiffness(mesh, C)
    if f_weight is None:
        return solve_free(mesh, K, f_lateral)
    sigma0 = lin_stress(mesh, solve_free(mesh, K, f_weight), C)
    return solve_free(mesh, K + geometric_stiffness(mesh, sigma0), f_lateral + f_weight)


def svk(mesh, u, C):
    """Total Lagrangian St Venant-Kirchhoff at the state u: internal forces
    int P : grad(N) and the tangent matrix (material + geometric part)."""
    F = np.eye(2) + gradients(mesh, u)
    Egl = 0.5 * (np.einsum('egkI,egkJ->egIJ', F, F) - np.eye(2))
    S = np.einsum('IJKL,egKL->egIJ', C, Egl)
    P = np.einsum('egiI,egIJ->egiJ', F, S)
    fint = np.einsum('g,gaJ,egiJ->eai', mesh.wdet, mesh.dN, P).reshape(-1, 18)
    # dP_iJ/dF_mL = delta_im S_JL + F_iI C_IJKL F_mK (C's minor symmetry)
    A = (np.einsum('im,egJL->egiJmL', np.eye(2), S)
         + np.einsum('egiI,IJKL,egmK->egiJmL', F, C, F, optimize=True))
    return assemble_vector(mesh, fint), assemble(mesh, element_matrices(mesh, A))


def nonlinear(mesh, C, load, steps=4, tol=1e-9, max_iter=60):
    """Newton on the load, applied in steps equal increments: a force vector
    (dead load) or a function (u, factor) -> forces for a load that follows
    the deformation (then the tangent leaves out the load's own stiffness, so
    the iteration is a quasi-Newton one). Converged when a correction is below
    tol times the displacement (the residual itself stalls at round-off,
    E h eps, far above a relative tolerance for small loads)."""
    ext = load if callable(load) else (lambda u, s: s * load)
    u = np.zeros(mesh.ndof)
    for k in range(1, steps + 1):
        for _ in range(max_iter):
            fint, KT = svk(mesh, u, C)
            du = solve_free(mesh, KT, ext(u, k / steps) - fint)
            u += du
            if np.max(np.abs(du)) <= tol * np.max(np.abs(u)):
                break
        else:
            raise RuntimeError(f'plate_fe: Newton did not converge in {max_iter} '
                               f'iterations at load step {k}/{steps} (nx = {mesh.nx})')
    return u


def follower_water(mesh, u, h1, h2):
    """What real still water does, for comparison with the dead load: the
    pressure rho_w g (h - y) at each face point's current height, normal to the
    deformed face. Per reference length the force is p (t_y, -t_x) on x = 0
    and -p (t_y, -t_x) on x = b, t = dx/dY the face's current tangent. Each
    edge is split where its current height crosses h (the kink)."""
    f = np.zeros(mesh.ndof)
    for col, h, sign in ((0, h1, 1.0), (mesh.cols - 1, h2, -1.0)):
        for j in range(mesh.ny):
            nodes = (2 * j + np.arange(3)) * mesh.cols + col
            pos = np.array([mesh.node_xy(k) for k in nodes]) + u[2 * nodes[:, None] + np.arange(2)]
            # current height yc(xi) = sum N_a y_a, a quadratic: its crossings of h
            c2 = 0.5 * (pos[0, 1] + pos[2, 1]) - pos[1, 1]
            c1 = 0.5 * (pos[2, 1] - pos[0, 1])
            roots = np.roots([c2, c1, pos[1, 1] - h]) if abs(c2) > 1e-300 else [(h - pos[1, 1]) / c1]
            cuts = [-1.0] + sorted(r.real for r in np.atleast_1d(roots)
                                   if abs(r.imag) < 1e-14 and -1 < r.real < 1) + [1.0]
            for a, c in zip(cuts[:-1], cuts[1:]):
                xi = 0.5 * (a + c) + 0.5 * (c - a) * GAUSS_X
                N, dN = lagrange2(xi)
                yc = N @ pos[:, 1]
                t = dN @ pos * (2 / mesh.hy)             # dx/dY at the points
                p = RHO_W * G * np.clip(h - yc, 0, None)
                w = GAUSS_W * 0.5 * (c - a) * mesh.hy / 2  # reference length
                fx = sign * p * t[:, 1] * w
                fy = -sign * p * t[:, 0] * w
                f[2 * nodes] += N.T @ fx
                f[2 * nodes + 1] += N.T @ fy
    return f


def face_area(mesh, u, col, h, n=64):
    """The room (m^2 per metre) the face x = const (column col) has moved
    toward +x below the level h: the integral of u_x over 0 <= Y < h (Gauss-
    Legendre; small vertical displacements, as the levels' change is small)."""
    x = 0.0 if col == 0 else mesh.b
    xg, wg = np.polynomial.legendre.leggauss(n)
    ys = 0.5 * h * (xg + 1.0)
    return float(sum(0.5 * h * w * mesh.interp(u, x, y)[0] for y, w in zip(ys, wg)))


def plate_solution(dp, weight=True, nonlinear_=False, nx=4, nu=0.0, b=PLATE['b'],
                   L=PLATE['L'], E=PLATE['E'], rho_s=PLATE['rho_s'], h1=None, h2=None,
                   follower=False, fixed_volume=False):
    """The plate at rest: u_x (m) at the probe (dp/2, L - dp/2) and at the top's
    middle (b/2, L), as a dict {'probe', 'top_mid'}. follower (nonlinear only):
    the water pressure at the current positions, normal to the deformed faces,
    in place of the dead load. fixed_volume: the basins are closed, so the
    bent plate lowers the left level by the room it gives that basin over its
    width and raises the right one likewise (iterated to 1e-9 m); the dict
    then also holds the levels h1, h2 (m)."""
    h1 = PLATE['h1'] - dp / 2 if h1 is None else h1
    h2 = PLATE['h2'] - dp / 2 if h2 is None else h2
    if fixed_volume:
        h10, h20, mesh = h1, h2, Mesh(nx, 7 * nx, b, L)
        for _ in range(30):
            r = plate_solution(dp, weight, nonlinear_, nx, nu, b, L, E, rho_s, h1, h2, follower)
            u = r['u']
            n1 = h10 - face_area(mesh, u, 0, h1) / BASINS['w1']
            n2 = h20 + face_area(mesh, u, mesh.cols - 1, h2) / BASINS['w2']
            done = abs(n1 - h1) < 1e-9 and abs(n2 - h2) < 1e-9
            h1, h2 = n1, n2
            if done:
                return dict(r, h1=h1, h2=h2)
        raise RuntimeError('plate_fe: the fixed-volume levels did not settle in 30 solves')
    mesh = Mesh(nx, 7 * nx, b, L)
    C = elasticity(E, nu)
    f_lat = water_load(mesh, h1, h2)
    f_w = weight_load(mesh, rho_s) if weight else None
    if nonlinear_ and follower:
        f_dead = f_w if weight else 0.0
        u = nonlinear(mesh, C, lambda u, s: s * (follower_water(mesh, u, h1, h2) + f_dead))
    elif nonlinear_:
        u = nonlinear(mesh, C, f_lat + (f_w if weight else 0.0))
    else:
        u = linearised(mesh, C, f_lat, f_w)
    return dict(probe=float(mesh.interp(u, dp / 2, L - dp / 2)[0]),
                top_mid=float(mesh.interp(u, b / 2, L)[0]), u=u)


def plate_tip(dp, weight=True, nonlinear=False, nx=4, nu=0.0, b=PLATE['b'], L=PLATE['L'],
              E=PLATE['E'], rho_s=PLATE['rho_s'], h1=None, h2=None, follower=False):
    """u_x (m) at the probe (dp/2, L - dp/2) of the plate at rest."""
    return plate_solution(dp, weight, nonlinear, nx, nu, b, L, E, rho_s, h1, h2,
                          follower)['probe']


# ---------------------------------------------------------------- convergence

def richardson(values, ratio=2.0):
    """Extrapolates a sequence on meshes refined by ratio, from its last three:
    (value, observed order, estimated error). The error is the change from the
    finest mesh to the extrapolation and, with four or more meshes, the change
    of the extrapolation when the finest mesh is added, whichever is larger
    (conservative: a sequence not yet in its asymptotic range shows a large
    error). A non-monotone sequence has no order: its last value is returned
    with the last change as the error."""
    def extrap(v0, v1, v2):
        d1, d2 = v1 - v0, v2 - v1
        if d1 == 0 or d2 == 0 or d1 * d2 < 0:
            return v2, float('nan')
        p = math.log(d1 / d2) / math.log(ratio)
        return v2 + d2 / (ratio ** p - 1), p
    value, p = extrap(*values[-3:])
    err = abs(value - values[-1]) if p == p else abs(values[-1] - values[-2])
    if len(values) >= 4:
        err = max(err, abs(value - extrap(*values[-4:-1])[0]))
    return value, p, err


def default_meshes():
    return (2, 4, 8, 16) if SPARSE else (2, 4, 8)


def converged(dp, weight=True, nonlinear=False, meshes=None, key='probe', follower=False):
    """(value, estimated error) of the plate's u_x (m) at the probe (key
    'top_mid': at (b/2, L)), extrapolated from nx = 2, 4, 8 (and 16 with
    scipy). converged_table gives the details."""
    r = converged_table(dp, weight, nonlinear, meshes, follower)
    return r[key]['value'], r[key]['error']


def converged_table(dp, weight=True, nonlinear=False, meshes=None, follower=False,
                    fixed_volume=False):
    """For the probe and the top's middle: the values on each mesh, the
    extrapolated value, its estimated error and the observed order; and the
    wall time (s). fixed_volume: also the levels on the finest mesh."""
    meshes = meshes or default_meshes()
    t0 = time.time()
    sols = [plate_solution(dp, weight, nonlinear, nx, follower=follower, fixed_volume=fixed_volume)
            for nx in meshes]
    out = dict(meshes=list(meshes), seconds=time.time() - t0)
    if fixed_volume:
        out['levels'] = (sols[-1]['h1'], sols[-1]['h2'])
    for key in ('probe', 'top_mid'):
        vals = [s[key] for s in sols]
        v, p, e = richardson(vals)
        out[key] = dict(values=vals, value=v, order=p, error=e)
    return out


# ---------------------------------------------------------------- beam theory

def euler_bernoulli_tip(dp, weight=True, b=PLATE['b'], L=PLATE['L'], E=PLATE['E'],
                        rho_s=PLATE['rho_s'], h1=None, h2=None):
    """The beam theory the FE is compared with (bench/hard_cases.py's
    rest_analytic calls it with the case's levels): the tip deflection (m) at
    y = L - dp/2 of the Euler-Bernoulli
    cantilever (EI = E b^3 / 12, E as given, no plane-strain factor) under the
    net still-water load, with the own weight as a beam-column (the part above
    a section, rho_s g b per metre of height, hangs over it at its deflected
    position), solved by fixed-point iteration."""
    h1 = PLATE['h1'] - dp / 2 if h1 is None else h1
    h2 = PLATE['h2'] - dp / 2 if h2 is None else h2
    s = np.linspace(0, L, 2001)
    q = RHO_W * G * (np.clip(h1 - s, 0, None) - np.clip(h2 - s, 0, None))
    mu = rho_s * G * b if weight else 0.0
    EI = E * b ** 3 / 12

    def tail(f):  # int_s^L f(t) dt, for every s
        c = np.concatenate([[0], np.cumsum(0.5 * (f[1:] + f[:-1]) * np.diff(s))])
        return c[-1] - c

    def twice(k):  # w from w'' = k, w(0) = w'(0) = 0
        slope = np.concatenate([[0], np.cumsum(0.5 * (k[1:] + k[:-1]) * np.diff(s))])
        return np.concatenate([[0], np.cumsum(0.5 * (slope[1:] + slope[:-1]) * np.diff(s))])
    Mq = tail(q * s) - s * tail(q)   # M(s) = int_s^L q(t) (t - s) dt
    w = np.zeros_like(s)
    for _ in range(200):
        wn = twice((Mq + mu * (tail(w) - (L - s) * w)) / EI)
        if np.max(np.abs(wn - w)) < 1e-13:
            break
        w = wn
    return float(np.interp(L - dp / 2, s, wn))


# ---------------------------------------------------------------- validation

def slender_cantilever(nx=2, slender=50, b=0.012, E=1.0e6, nu=0.0, p=1.0):
    """The FE against beam theory: a cantilever L = slender b under a uniform
    pressure p on x = 0, no weight. Returns (FE u_x at (b/2, L), Euler-Bernoulli,
    Euler-Bernoulli + Timoshenko shear). Plane strain: E' = E / (1 - nu^2) in
    bending, G = E / (2 (1 + nu)) in shear, kappa = 10 (1 + nu) / (12 + 11 nu)
    (Cowper's rectangle; 5/6 at nu = 0, Timoshenko's value too)."""
    L = slender * b
    mesh = Mesh(nx, slender * nx, b, L)
    f = edge_load(mesh, 0, lambda y: np.full_like(y, p))
    u = linearised(mesh, elasticity(E, nu), f)
    Ep, Gs = E / (1 - nu ** 2), E / (2 * (1 + nu))
    kappa = 10 * (1 + nu) / (12 + 11 * nu)
    eb = p * L ** 4 / (8 * Ep * b ** 3 / 12)
    return float(mesh.interp(u, b / 2, L)[0]), eb, eb + p * L ** 2 / (2 * kappa * Gs * b)


def buckling_factor(nx=1, slender=50, b=0.012, E=1.0e6, nu=0.0, rho_s=PLATE['rho_s']):
    """The load factor lambda at which K + lambda K_G(sigma0 of the weight)
    turns singular, for a column L = slender b clamped at its foot. Returns
    (lambda, Greenhill's lambda: lambda rho_s g b = 7.837 E I / L^3).
    Dense (a small problem): with K = R R^T (Cholesky), 1/lambda is the largest
    eigenvalue of R^-1 (-K_G) R^-T, -K_G being positive under compression."""
    L = slender * b
    mesh = Mesh(nx, slender * nx, b, L)
    C = elasticity(E, nu)
    K = stiffness(mesh, C)
    sigma0 = lin_stress(mesh, solve_free(mesh, K, weight_load(mesh, rho_s)), C)
    KG = geometric_stiffness(mesh, sigma0)
    fr = mesh.free
    K, KG = (A.toarray() if hasattr(A, 'toarray') else A for A in (K, KG))
    Ri = np.linalg.inv(np.linalg.cholesky(K[np.ix_(fr, fr)]))
    M = Ri @ (-KG[np.ix_(fr, fr)]) @ Ri.T
    lam = 1.0 / np.linalg.eigvalsh(0.5 * (M + M.T))[-1]
    return float(lam), 7.837 * E * b ** 3 / 12 / L ** 3 / (rho_s * G * b)


def validate():
    t0 = time.time()
    fe, eb, ts = slender_cantilever()
    t1 = time.time()
    print(f'slender cantilever L/b = 50, uniform pressure, nx = 2, ny = 100: FE {fe:.6e} m, '
          f'E-B {eb:.6e} (FE/E-B - 1 = {100 * (fe / eb - 1):+.4f}%), E-B + shear (k = 5/6) '
          f'{ts:.6e} (FE/(E-B+shear) - 1 = {100 * (fe / ts - 1):+.4f}%)  [{t1 - t0:.1f} s]')
    for nx in (1, 2):
        t1 = time.time()
        lam, ref = buckling_factor(nx=nx)
        print(f'self-weight buckling L/b = 50, nx = {nx}: lambda {lam:.7f}, Greenhill {ref:.7f} '
              f'({100 * (lam / ref - 1):+.3f}%)  [{time.time() - t1:.1f} s]')


# ---------------------------------------------------------------- CLI

MODES = {'linear': (False, False), 'nonlinear': (True, False), 'follower': (True, True)}


def mode_name(mode, weight):
    return {'linear': 'linearised (K + K_G)' if weight else 'linear',
            'nonlinear': 'nonlinear (TL, St Venant-Kirchhoff), dead loads',
            'follower': 'nonlinear, water pressure following the faces (not the brief\'s '
                        'dead load: what real water does)'}[mode]


def table(dps, weight, mode, meshes, fixed_volume=False):
    """One table: per dp, u_x at the probe on each mesh, extrapolated, its
    estimated error and observed order, Euler-Bernoulli beside, u_x at the
    top's middle (extrapolated) and the wall time."""
    nonlin, follower = MODES[mode]
    print(f'weight: {"yes" if weight else "no"}; {mode_name(mode, weight)}; '
          f'meshes nx = {", ".join(map(str, meshes))} (ny = 7 nx); u_x in mm'
          + ('; levels of fixed volumes' if fixed_volume else ''))
    cols = ' '.join(f'{"nx=" + str(n):>9}' for n in meshes)
    print(f'{"dp (mm)":>8} {cols} {"extrap":>9} {"+-":>8} {"order":>5} {"E-B":>9} '
          f'{"FE/E-B":>7} {"top mid":>9} {"time s":>6}')
    for dp in dps:
        r = converged_table(dp, weight, nonlin, meshes, follower, fixed_volume)
        pr, eb = r['probe'], euler_bernoulli_tip(dp, weight)
        if fixed_volume:
            print(f'{"":8} levels {1e3 * r["levels"][0]:.4f} / {1e3 * r["levels"][1]:.4f} mm '
                  f'(from {1e3 * (PLATE["h1"] - dp / 2):.4f} / {1e3 * (PLATE["h2"] - dp / 2):.4f}); '
                  'E-B at the initial levels')
        vals = ' '.join(f'{1e3 * v:9.5f}' for v in pr['values'])
        print(f'{1e3 * dp:8.3f} {vals} {1e3 * pr["value"]:9.5f} {1e3 * pr["error"]:8.1e} '
              f'{pr["order"]:5.2f} {1e3 * eb:9.5f} {pr["value"] / eb:7.4f} '
              f'{1e3 * r["top_mid"]["value"]:9.5f} {r["seconds"]:6.1f}', flush=True)
        if not pr['error'] < 1e-3 * abs(pr['value']):
            print(f'plate_fe: dp = {dp}: estimated error {pr["error"]:.2e} m is not below 0.1%',
                  file=sys.stderr)


def write_json(path, dps, meshes):
    """u_x at the probe (m), extrapolated, per dp, mode and weight, with its
    estimated error and Euler-Bernoulli beside: the reference table that
    bench/hard_cases.py reads (the nonlinear solves take minutes without
    scipy, too long to repeat in its report)."""
    out = {'source': 'bench/plate_fe.py --json ' + path + ' --dp ' + ' '.join(map(str, dps)),
           'meshes': list(meshes), 'dp': {}}
    for dp in dps:
        row = {}
        for weight in (True, False):
            for mode, (nonlin, follower) in MODES.items():
                r = converged_table(dp, weight, nonlin, meshes, follower)['probe']
                row[f'{mode}{"" if weight else "_no_weight"}'] = [r['value'], r['error']]
            row['euler_bernoulli' + ('' if weight else '_no_weight')] = euler_bernoulli_tip(dp, weight)
        # the closed basins' levels (--fixed-volume): what the coupled runs,
        # which hold the water's volume, should approach
        r = converged_table(dp, True, True, meshes, True, fixed_volume=True)
        row['follower_fixed_volume'] = [r['probe']['value'], r['probe']['error']]
        row['fixed_volume_levels'] = list(r['levels'])
        out['dp'][repr(dp)] = row
        print(f'plate_fe: dp {dp} done', file=sys.stderr, flush=True)
    with open(path, 'w') as f:
        json.dump(out, f, indent=1)
        f.write('\n')


def main():
    global SPARSE
    ap = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    ap.add_argument('--dp', type=float, nargs='+', default=[0.003, 0.0015, 0.001, 0.00075])
    ap.add_argument('--no-weight', action='store_true')
    ap.add_argument('--nonlinear', action='store_true', help='geometrically nonlinear, dead loads')
    ap.add_argument('--follower', action='store_true',
                    help='nonlinear with the pressure at the current faces')
    ap.add_argument('--both', action='store_true',
                    help='with and without weight, linearised, nonlinear and follower')
    ap.add_argument('--dense', action='store_true', help='numpy dense solves (as on CI)')
    ap.add_argument('--fixed-volume', action='store_true',
                    help='the levels the closed basins hold as the plate bends')
    ap.add_argument('--validate', action='store_true')
    ap.add_argument('--max-nx', type=int, default=None)
    ap.add_argument('--json', metavar='PATH',
                    help='write every mode, with and without weight, per dp (m) to PATH: '
                         'bench/hard_cases.py reads bench/plate_fe_reference.json')
    a = ap.parse_args()
    if a.dense:
        SPARSE = False
    if a.validate:
        validate()
        return
    meshes = default_meshes()
    if a.max_nx:
        meshes = tuple(n for n in (2, 4, 8, 16, 32) if n <= a.max_nx)
    if a.json:
        write_json(a.json, a.dp, meshes)
        return
    mode = 'follower' if a.follower else 'nonlinear' if a.nonlinear else 'linear'
    combos = ([(w, m) for m in MODES for w in (True, False)] if a.both
              else [(not a.no_weight, mode)])
    for w, m in combos:
        table(a.dp, w, m, meshes, a.fixed_volume)
        print()


if __name__ == '__main__':
    main()
