#!/usr/bin/python3
"""Latency-bandwidth model of Flotsam's step on P ranks (docs/performance.md, "Scaling model").

time per step = compute + sum over the messages of one rank (alpha + bytes / beta)
                + per allreduce ceil(log2 P) (alpha + bytes / beta) + the balance check's allgather / 20

compute: the rank's particles over the measured 1-rank rate (particle-steps/s of flotsam_bench,
build/release). The messages are those scripts/bench_communication counts, written as functions of the
rank's box of L cells per axis (a rank with a neighbour on every face, the slowest one):
  ghost-node sums (MUSL: two per step): per face neighbour one message each, (1 + 2 dim) and dim rows
      of 8-byte values over the (L + 1)^(dim - 1) nodes of the shared plane (multilinear shape);
  migration: per face neighbour one message of the particles that crossed (their number travels with
      them), phi x (particles of one cell layer) x record bytes, phi measured on the collapsing columns;
  the step's one reduction (time step, extent, the time loop's flags: 12 doubles) and, every 20 steps,
      the balance check's allgather of P 8-byte counts.
Messages are not overlapped with each other or with compute (an upper bound on the cost).

usage: scripts/scaling_model.py [rate_2d rate_3d]   (particle-steps/s on one rank; defaults: measured)
"""
import math
import sys

# measured on the 2-core development machine 2026-11-25 (docs/performance.md): 1-rank particle-steps/s of
# flotsam_bench on the bench water columns (300 and 100 steps), Release build
RATE = {2: 12.06e6, 3: 5.41e6}
if len(sys.argv) == 3:
    RATE = {2: float(sys.argv[1]), 3: float(sys.argv[2])}
PPC = {2: 4, 3: 8}                  # particles per cell of the bench columns (2 per direction)
RECORD = {2: 12 * 8, 3: 16 * 8}     # bytes of one migrating particle (particle_set%record_size)
# particles crossing one face per step / particles of one cell layer at that face: measured on the
# collapsing columns in full flow (flotsam, 4 ranks, scripts in docs/performance.md)
PHI = {2: 0.0007, 3: 0.0002}
NETWORKS = {"fast (1 us, 10 GB/s)": (1.0e-6, 10.0e9), "Ethernet (25 us, 1.2 GB/s)": (25.0e-6, 1.2e9)}
REDUCTIONS_PER_STEP = 1
REDUCTION_BYTES = 12 * 8
BALANCE_INTERVAL = 20


def rank_grid(ranks, dim):
    """Balanced factors of ranks over dim axes, largest first (as MPI_Dims_create)."""
    dims = [1] * dim
    n = ranks
    p = 2
    factors = []
    while n > 1:
        while n % p == 0:
            factors.append(p)
            n //= p
        p += 1
    for f in sorted(factors, reverse=True):
        dims[dims.index(min(dims))] *= f
    return sorted(dims, reverse=True)


def rank_grids(ranks, dim):
    """How many rank grids load_balance tries (every ordered factorisation into dim factors)."""
    if dim == 2:
        return sum(1 for a in range(1, ranks + 1) if ranks % a == 0)
    return sum(1 for a in range(1, ranks + 1) if ranks % a == 0
               for b in range(1, ranks // a + 1) if (ranks // a) % b == 0)


def step(dim, ranks, box, alpha, beta):
    """Seconds per step of the slowest rank with a box of box[k] cells along axis k."""
    particles = PPC[dim] * math.prod(box)
    compute = particles / RATE[dim]
    dims = rank_grid(ranks, dim)
    halo = migration = 0.0
    messages = 0
    halo_bytes = 0.0
    for k in range(dim):
        if dims[k] == 1:
            continue
        others = [box[j] for j in range(dim) if j != k]
        plane_nodes = math.prod(n + 1 for n in others)
        layer = PPC[dim] * math.prod(others)
        for _ in range(2):                      # both faces of an inner rank
            for rows in (1 + 2 * dim, dim):     # the two ghost-node sums
                halo += alpha + 8 * rows * plane_nodes / beta
                halo_bytes += 8 * rows * plane_nodes
            migration += alpha + PHI[dim] * layer * RECORD[dim] / beta
            messages += 3
    levels = math.ceil(math.log2(ranks)) if ranks > 1 else 0
    reductions = REDUCTIONS_PER_STEP * levels * (alpha + REDUCTION_BYTES / beta)
    balance = (levels * alpha + 8 * (ranks - 1) / beta) / BALANCE_INTERVAL if ranks > 1 else 0.0
    return dict(particles=particles, compute=compute, halo=halo, migration=migration, reductions=reductions,
                balance=balance, messages=messages, halo_bytes=halo_bytes, dims=dims)


def table(title, cases):
    print(f"\n{title}")
    nets = list(NETWORKS)
    print(f"{'dim':>3} {'ranks':>6} {'rank grid':>11} {'particles/rank':>14} {'box cells':>13} {'msgs':>5} "
          f"{'halo kB':>8} {'compute ms':>10} " + " ".join(f"{'comm us':>8} {'eff %':>6}" for _ in nets))
    for dim, ranks, box in cases:
        figures = [step(dim, ranks, box, *NETWORKS[n]) for n in nets]
        f = figures[0]
        line = (f"{dim:>3} {ranks:>6} {'x'.join(map(str, f['dims'])):>11} {f['particles']:>14.0f} "
                f"{'x'.join(f'{b:.1f}' for b in box):>13} {f['messages']:>5} {f['halo_bytes'] / 1e3:>8.1f} "
                f"{1e3 * f['compute']:>10.2f}")
        for g in figures:
            comm = g['halo'] + g['migration'] + g['reductions'] + g['balance']
            line += f" {1e6 * comm:>8.1f} {100 * g['compute'] / (g['compute'] + comm):>6.1f}"
        print(line)


def main():
    print("networks: " + "; ".join(NETWORKS) + f". 1-rank rates: 2-D {RATE[2]:.3g}, 3-D {RATE[3]:.3g} particle-steps/s")
    weak = []
    for dim in (2, 3):
        side = (100_000 / PPC[dim]) ** (1 / dim)
        for ranks in (2, 8, 64, 1024):
            weak.append((dim, ranks, [side] * dim))
    table("Weak scaling: 100 000 particles per rank (cubic boxes); eff = compute / (compute + comm)", weak)
    strong = []
    for dim in (2, 3):
        cells = 10_000_000 / PPC[dim]
        side = cells ** (1 / dim)
        for ranks in (2, 8, 64, 1024):
            dims = rank_grid(ranks, dim)
            strong.append((dim, ranks, [side / d for d in dims]))
    table("Strong scaling: 10 M particles in a cube of cells (2-D: a square)", strong)
    print("\nThe load balancer's layout search (only when the largest rank holds > 1.1 x the mean):")
    for dim in (2, 3):
        for ranks in (8, 64, 1024):
            grids = rank_grids(ranks, dim)
            print(f"  {dim}-D, {ranks:>5} ranks: {grids:>3} rank grids tried, each one pass over the rank's particles; "
                  f"box-count reduction {8 * ranks * grids / 1e3:.1f} kB")


if __name__ == "__main__":
    main()
