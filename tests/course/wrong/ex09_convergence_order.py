# The ratio of the logarithms upside down.
# expect: inverse of 2
def convergence_order(r):
    r = np.asarray(r, dtype=float)
    return np.log(r[-2] / r[-3]) / np.log(r[-1] / r[-2])
