"""The peer of tests/heights_peer.rs: bounded linear least squares by SciPy.

Reads a JSON list of problems {"a": rows, "b": [...], "upper": [...]} from standard input and
prints, for each, {"x": [...], "cost": ||A x - b||^2} from scipy.optimize.lsq_linear with
bounds 0 <= x <= upper (method "bvls", Stark and Parker's algorithm, an implementation
independent of dressform's).
"""
import json
import sys

import numpy as np
from scipy.optimize import lsq_linear

out = []
for problem in json.load(sys.stdin):
    a = np.array(problem["a"], dtype=float)
    b = np.array(problem["b"], dtype=float)
    upper = np.array(problem["upper"], dtype=float)
    result = lsq_linear(a, b, bounds=(np.zeros_like(upper), upper), method="bvls", tol=1e-12)
    x = np.clip(result.x, 0.0, upper)
    out.append({"x": x.tolist(), "cost": float(np.sum((a @ x - b) ** 2))})
json.dump(out, sys.stdout)
