# Stick and slip told apart by the traction, not by the trial tau = t_T + c_T dg_T.
# expect: C_T \(Coulomb
def C_T(t_T, dg_T, xi, c_T, mu):
    t_T, dg_T, xi = (np.asarray(a, dtype=float) for a in (t_T, dg_T, xi))
    closed = xi >= 0.0
    Y = mu * np.where(closed, xi, 0.0)
    stick = closed & (np.abs(t_T) <= Y)
    slip = closed & ~stick
    C = np.where(stick, -c_T * dg_T, np.where(slip, t_T - np.sign(t_T) * Y, t_T))
    return (C, np.where(stick, 0.0, 1.0), np.where(stick, -c_T, 0.0), np.where(slip, -np.sign(t_T) * mu, 0.0))
