"""The live preview's resolution while a pose is dragged or played: the one that keeps the rate (#85 item 4).

    each live picture's cost (the live thread's pose, body and surface, plus the last draw), at its factor
        --the median of the last WINDOW at the factor in use--> over the budget (1 / RATE): a coarser factor
                                                                  far under it (FINER times less): a finer one
        --> the factor of the next live picture (1 full size, 2 half, 4 quarter); the verdict says which

Why it adapts rather than picking by size alone: the size rule (preview.live_factor) guessed a body of 8 M
voxels redone live at full size; on this machine's software GL the mannequin's full-size surface and draw
then took 110 ms a picture (4 a second), and a machine with a GPU draws the frog's half-size body in a few
ms. A picture's cost at the next finer factor is taken as FINER times its cost: a surface and its draw grow
with the body's area, four times a halving of the voxel, its redo with the volume, eight. Once a drag has gone
finer and come back, the step's real ratio is known and used instead of that guess: the frog's quarter-size
pictures cost 15 ms (x 5 = 75 ms: "go finer"), its half-size ones 120 ms (the body's redo grew eight-fold), and
without the ratio the factor went back and forth for the whole drag, every change a picture of a whole grid.
Release (or pause) draws the full picture at full size whatever the live factor.
"""

from __future__ import annotations

import statistics
from collections.abc import Callable

RATE = 10.0  # live pictures a second the studio keeps (#85's goal), when it can
WINDOW = 3  # pictures at one factor before it is judged: one slow picture (a first frame) changes nothing
FINER = 5.0  # a picture's cost at the next finer factor, times its cost here (4 for area, 8 for volume)
COARSEST = 4
CHOICES = ("auto", "full", "half", "quarter")
FIXED = {"full": 1, "half": 2, "quarter": 4}


class LiveResolution:
    """Picks each live picture's factor: :attr:`choice` ``auto`` adapts (module docstring), else fixed."""

    def __init__(self, choice: str = "auto", rate: float = RATE):
        if choice not in CHOICES:
            raise ValueError(f"live resolution must be one of {', '.join(CHOICES)}, got {choice!r}")
        self.choice, self.budget = choice, 1.0 / rate
        self.factor: int | None = None  # auto: the factor in use (None: the size rule's, on the first picture)
        self._costs: list[float] = []
        self._left_for_finer: dict[int, float] = {}  # factor -> its cost when the picture went finer from it
        self._ratio: dict[int, float] = {}  # factor -> (cost at factor / 2) / (cost at factor), seen in a round trip

    def factor_for(self, size_rule: Callable[[], int]) -> int:
        """The next live picture's factor; ``size_rule()``: the size rule's, asked only for an auto first picture."""
        if self.choice != "auto":
            return FIXED[self.choice]
        if self.factor is None:
            self.factor = int(size_rule())
        return self.factor

    def took(self, factor: int, seconds: float) -> None:
        """A live picture at ``factor`` cost ``seconds`` (made and drawn); moves the factor when WINDOW of them
        at the factor in use say so."""
        if self.choice != "auto" or factor != self.factor:
            return
        self._costs = (self._costs + [float(seconds)])[-WINDOW:]
        if len(self._costs) < WINDOW:
            return
        cost = statistics.median(self._costs)
        if cost > self.budget and self.factor < COARSEST:
            coarser = self.factor * 2
            if coarser in self._left_for_finer:  # back from a step finer: its real ratio is known now
                self._ratio[coarser] = cost / max(self._left_for_finer.pop(coarser), 1e-9)
            self.factor, self._costs = coarser, []
        elif self.factor > 1 and cost * self._ratio.get(self.factor, FINER) < self.budget:
            self._left_for_finer[self.factor] = cost
            self.factor, self._costs = self.factor // 2, []

    def reset(self) -> None:
        """Another body or mode: the next picture starts again from the size rule, no ratio known."""
        self.factor, self._costs, self._left_for_finer, self._ratio = None, [], {}, {}
