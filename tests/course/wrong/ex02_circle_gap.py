# The normal turned inwards.
# expect: points into the disc
def circle_gap(x_s, centre, R):
    d = np.asarray(x_s, dtype=float) - np.asarray(centre, dtype=float)
    r = np.linalg.norm(d, axis=1)
    return r - R, -d / r[:, None]
