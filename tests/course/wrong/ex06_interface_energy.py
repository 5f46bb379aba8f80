# The stick springs forgotten: only the penalty potential is counted.
# expect: stick springs
def interface_energy(g_N, t_T, weights, c_N, m, c_T):
    g_N = np.asarray(g_N, dtype=float)
    approach = np.where(g_N < 0.0, -g_N, 0.0)
    return float(np.sum(np.asarray(weights) * c_N * approach ** (m + 1.0) / (m + 1.0)))
