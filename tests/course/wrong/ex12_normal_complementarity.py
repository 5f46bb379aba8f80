# C_N written as max(0, xi) - p: the sign flipped.
# expect: wrong sign
def C_N(t_N, g_N, c_N):
    p = -np.asarray(t_N, dtype=float)
    g = np.asarray(g_N, dtype=float)
    closed = p - c_N * g >= 0.0
    C = np.where(closed, -c_N * g, -p)
    return C, np.where(closed, 0.0, 1.0), np.where(closed, -c_N, 0.0)
