# The sign of t_T kept: the slip condition bounds |t_T|, and a node pushed backwards looks safe.
# expect: where t_T < 0
def slip_margin(t_N, t_T, law):
    p = np.abs(np.asarray(t_N, dtype=float))
    return np.asarray(t_T, dtype=float) - law.slip_bound(p, np.zeros_like(p))[0]
