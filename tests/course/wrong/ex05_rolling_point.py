# The spin-up forgotten: the ring is taken to roll when its centre would stop.
# expect: contact point stops
def rolling_point(v0, mu, g, a, k2):
    t_star = v0 / (mu * g)
    return t_star, v0 * t_star - 0.5 * mu * g * t_star**2, v0 - mu * g * t_star
