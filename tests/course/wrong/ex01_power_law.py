# The derivative without the exponent's factor m: the check should say "off by a factor".
# expect: dt_N/dg_N .*off by a factor 0\.4
def power_law(g_N, c_N, m):
    g_N = np.asarray(g_N, dtype=float)
    approach = np.where(g_N < 0.0, -g_N, 0.0)
    return -c_N * approach**m, np.where(g_N < 0.0, c_N * approach ** (m - 1.0), 0.0)
