# The angle left in radians.
# expect: radians
def escape_angle(p, alpha, beta, n):
    return np.arctan(alpha * np.asarray(p, dtype=float) ** (n - 1.0) + beta)
