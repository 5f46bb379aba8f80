# The penalty solution returned: c_N taken for a penalty, not a complementarity parameter.
# expect: penalty answer
def semismooth_1dof(k, P, g0, c_N, tol, max_iterations=20):
    u = P / k
    if u > g0:
        u = (P + c_N * g0) / (k + c_N)
    return u, max(0.0, c_N * (u - g0)), 1
