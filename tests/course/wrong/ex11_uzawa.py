# The multiplier never updated: the penalty solution, returned as converged.
# expect: penalty solution
def uzawa_1dof(k, P, g0, c_N, tol, max_updates=200):
    u = (P + c_N * g0) / (k + c_N)
    return u, min(0.0, c_N * (g0 - u)), 0
