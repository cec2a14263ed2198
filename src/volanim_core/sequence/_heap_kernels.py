"""The heap's numba kernel: landed voxels slide off until no slope is steeper than 45 degrees."""

from __future__ import annotations

from numba import njit


@njit(cache=True)
def settle(stacks, heights):
    """Topple grains between 4-neighbour columns until neighbouring heights differ by at most 1.

    ``stacks[x, y, h]``: the grain (an id, -1 = none) at height ``h`` of column ``(x, y)``;
    ``heights[x, y]``: how many grains the column holds. Both are changed in place. A
    column's top grain moves onto the top of a neighbour two or more lower (the sand-pile
    model: the slope settles at the angle of repose); the grid's edges are walls. Sweeps
    alternate direction so the heap does not lean the way the loop runs. Returns the moves.
    """
    nx, ny = heights.shape
    moves = 0
    sweep = 0
    moved = True
    while moved:
        moved = False
        forward = sweep % 2 == 0
        sweep += 1
        for a in range(nx):
            x = a if forward else nx - 1 - a
            for b in range(ny):
                y = b if forward else ny - 1 - b
                for k in range(4):
                    u = x + (1 if k == 0 else -1 if k == 1 else 0)
                    v = y + (1 if k == 2 else -1 if k == 3 else 0)
                    if u < 0 or u >= nx or v < 0 or v >= ny:
                        continue
                    while heights[x, y] - heights[u, v] > 1:
                        top = heights[x, y] - 1
                        stacks[u, v, heights[u, v]] = stacks[x, y, top]
                        stacks[x, y, top] = -1
                        heights[x, y] = top
                        heights[u, v] += 1
                        moves += 1
                        moved = True
    return moves
