# Boyle's law upside down: the pressure rises as the gas expands.
# expect: rises as the cork moves out
def gas_pressure(p0, V0, area, du, travel):
    du = np.asarray(du, dtype=float)
    return np.where(du < travel, p0 * (V0 + area * du) / V0, 0.0)
