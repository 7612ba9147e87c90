"""orbis.ba: "Bundle Adjustment in the Large" problems solved by orbis's own sparse solver.

Contract: ``read_bal(path)`` reads a problem-*.txt file into a ``BalProblem`` (cameras (N, 9):
angle-axis, translation, f, k1, k2; points (M, 3); observations as (camera_index, point_index,
pixels)); ``BalProblem(...)`` builds one from arrays; ``solve_bal(problem, huber=1.0,
max_iterations=50)`` solves it in place like ``orbis ba`` and returns initial_cost, final_cost
(Ceres' 1/2 sum rho), iterations, successful_steps, termination, sparse and seconds.
"""

from __future__ import annotations

from ._orbis import BalProblem, read_bal, solve_bal

__all__ = ["BalProblem", "read_bal", "solve_bal"]
