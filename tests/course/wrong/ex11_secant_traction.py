# The trapezoidal mean instead of the secant: its work is not the energy change.
# expect: energy\(g1\) - energy\(g0\)
def secant_traction(law, g0, g1):
    return float(0.5 * (law.traction(np.array([g0]))[0][0] + law.traction(np.array([g1]))[0][0]))
