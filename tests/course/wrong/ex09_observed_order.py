# The slope between the first and the last point only.
# expect: two points only
def observed_order(h, e):
    h, e = np.asarray(h, dtype=float), np.abs(np.asarray(e, dtype=float))
    return np.log(e[-1] / e[0]) / np.log(h[-1] / h[0])
