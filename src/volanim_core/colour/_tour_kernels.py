"""numba kernels for palette ordering: a shortest Hamiltonian path by local search.

The path is kept as ``P = [d, p1, ..., pN, d]`` where ``d`` is a dummy colour at
distance 0 from every colour: a closed tour through ``d`` is then exactly an
open path, and every move below only has to look at interior edges.
"""

from __future__ import annotations

import numpy as np
from numba import njit

EPS = 1e-9


@njit(cache=True)
def nearest_neighbour_path(D, start):
    """Greedy path from ``start``: always on to the nearest colour not yet visited."""
    n = D.shape[0]
    seen = np.zeros(n, np.bool_)
    path = np.empty(n, np.int64)
    path[0] = start
    seen[start] = True
    for k in range(1, n):
        cur = path[k - 1]
        best, best_d = -1, np.inf
        for j in range(n):
            if not seen[j] and D[cur, j] < best_d:
                best, best_d = j, D[cur, j]
        path[k] = best
        seen[best] = True
    return path


@njit(cache=True)
def path_length(D, path):
    total = 0.0
    for k in range(len(path) - 1):
        total += D[path[k], path[k + 1]]
    return total


@njit(cache=True)
def two_opt(D, P):
    """Reverse ``P[i+1..j]`` while that shortens the tour; returns whether anything changed."""
    m = len(P) - 1
    changed = False
    improved = True
    while improved:
        improved = False
        for i in range(m - 1):
            for j in range(i + 2, m):
                a, b, c, d = P[i], P[i + 1], P[j], P[j + 1]
                if D[a, c] + D[b, d] - D[a, b] - D[c, d] < -EPS:
                    P[i + 1:j + 1] = P[i + 1:j + 1][::-1].copy()
                    improved = changed = True
    return changed


@njit(cache=True)
def or_opt(D, P, max_segment):
    """Move a run of 1..``max_segment`` colours (either way round) to a better place; returns
    whether anything changed. With ``max_segment=1`` this is reinsertion of single colours."""
    m = len(P) - 1
    changed = False
    improved = True
    while improved:
        improved = False
        for length in range(1, max_segment + 1):
            s = 1
            while s + length - 1 <= m - 1:
                e = s + length - 1
                gain = D[P[s - 1], P[s]] + D[P[e], P[e + 1]] - D[P[s - 1], P[e + 1]]
                best, best_q, best_rev = -EPS, -1, False
                for q in range(m):
                    if s - 1 <= q <= e:
                        continue
                    base = D[P[q], P[q + 1]]
                    fwd = D[P[q], P[s]] + D[P[e], P[q + 1]] - base - gain
                    rev = D[P[q], P[e]] + D[P[s], P[q + 1]] - base - gain
                    if fwd < best:
                        best, best_q, best_rev = fwd, q, False
                    if rev < best:
                        best, best_q, best_rev = rev, q, True
                if best_q >= 0:
                    seg = P[s:e + 1].copy()
                    if best_rev:
                        seg = seg[::-1].copy()
                    rest = np.concatenate((P[:s], P[e + 1:]))
                    q = best_q if best_q < s else best_q - length  # position of P[q] in rest
                    P[:] = np.concatenate((rest[:q + 1], seg, rest[q + 1:]))
                    improved = changed = True
                else:
                    s += 1
    return changed


@njit(cache=True)
def improve(D, P, max_segment):
    """2-opt and Or-opt in turn until neither finds a shorter path (a local optimum of both)."""
    while True:
        a = two_opt(D, P)
        b = or_opt(D, P, max_segment)
        if not (a or b):
            return P
