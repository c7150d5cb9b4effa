#!/usr/bin/python3
"""The critical step of the explicit update with lumped mass, from the Fourier symbol of the stiffness of a
weakly compressible fluid (docs/theory.md, section 5.1).

On an unbounded regular grid (h = 1, rho = 1, c = 1) filled with material, the largest eigenvalue of
M_L^-1 K over all wave vectors is omega_max^2; the update (symplectic Euler: the velocities first, then the
positions and the stress with them) is stable for omega_max dt <= 2. The stiffness of a pressure
p = -K tr(eps) is K times the div-div form, K_ij,ab = integral of d_a N_i d_b N_j; with tensor-product
shape functions each entry is a product of 1-D integrals, and its Fourier sum a product of 1-D sums. The
lumped mass of every node is 1 (a partition of unity). Integrals are exact (Gauss on every polynomial
piece) or the particle quadrature of n x n (x n) particles per cell at the cells' lattice points.

    scripts/critical_step.py            prints omega_max, dt_crit [h / c] and Flotsam's CFL number at the
                                        limit (dt = cfl h / (sqrt(dim) c)) for linear and bspline2, 1-3-D
"""
import itertools

import numpy as np

SAMPLES = 33          # wave numbers per axis in [-pi, pi] (25 in 3-D); the maxima lie on that lattice
OFFSETS = np.arange(-3, 4)


def hat(x):
    return np.maximum(0.0, 1.0 - np.abs(x))


def hat_slope(x):
    return np.where(np.abs(x) < 1.0, -np.sign(x), 0.0)


def bspline2(x):
    a = np.abs(x)
    return np.where(a < 0.5, 0.75 - a * a, np.where(a < 1.5, 0.5 * (1.5 - a) ** 2, 0.0))


def bspline2_slope(x):
    a = np.abs(x)
    return np.where(a < 0.5, -2.0 * x, np.where(a < 1.5, -np.sign(x) * (1.5 - a), 0.0))


SHAPES = {"linear": (hat, hat_slope), "bspline2": (bspline2, bspline2_slope)}


def quadrature(rule, shape):
    """Points and weights along one axis over the cells near node 0. Particles sit in the grid cells
    [k, k + 1] at (m + 1/2) / n; exact integration uses Gauss on the polynomial pieces (a quadratic
    B-spline's knots lie at the half-integers)."""
    if rule == "exact":
        g, w = np.polynomial.legendre.leggauss(6)
        base, weights = (g + 1) / 2, w / 2
        shift = 0.5 if shape == "bspline2" else 0.0
    else:
        n = int(rule)
        base, weights, shift = (np.arange(n) + 0.5) / n, np.full(n, 1.0 / n), 0.0
    cells = np.arange(-5, 5)
    return (cells[:, None] + base[None, :] + shift).ravel(), np.tile(weights, len(cells))


def axis_sums(shape, rule, theta):
    """Fourier sums over the neighbours j of node 0 of the 1-D integrals N N_j, N' N_j, N N_j', N' N_j'."""
    f, slope = SHAPES[shape]
    x, w = quadrature(rule, shape)
    phase = np.exp(1j * theta * OFFSETS)
    integrals = np.array([[np.sum(w * a(x) * b(x - j)) for j in OFFSETS]
                          for a, b in ((f, f), (slope, f), (f, slope), (slope, slope))])
    return integrals @ phase


def largest_eigenvalue(shape, rule, dim):
    thetas = np.linspace(-np.pi, np.pi, SAMPLES if dim < 3 else 25)
    sums = {t: axis_sums(shape, rule, t) for t in thetas}
    largest = 0.0
    for wave in itertools.product(thetas, repeat=dim):
        k = np.ones((dim, dim), complex)
        for a in range(dim):
            for b in range(dim):
                for axis in range(dim):
                    mass, left, right, both = sums[wave[axis]]
                    k[a, b] *= both if a == b == axis else left if axis == a else right if axis == b else mass
        largest = max(largest, np.linalg.eigvalsh(0.5 * (k + k.conj().T)).max())
    return largest


def main():
    for shape in SHAPES:
        for dim in (1, 2, 3):
            for rule in ("exact", "2", "3"):
                omega = np.sqrt(largest_eigenvalue(shape, rule, dim))
                dt = 2.0 / omega
                print(f"{shape:9s} {dim}-D quadrature {rule:5s}: omega_max = {omega:.4f} c/h, dt_crit = {dt:.4f} h/c, "
                      f"CFL number at the limit {dt * np.sqrt(dim):.3f}")


if __name__ == "__main__":
    main()
