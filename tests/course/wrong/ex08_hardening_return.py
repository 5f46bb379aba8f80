# The hardening of the step itself left out of the consistency condition.
# expect: without hardening in the consistency condition
def hardening_return(t_bar, dg_T, p, q_bar, c_T, mu0, h):
    t_tr = t_bar + c_T * dg_T
    f = abs(t_tr) - (mu0 + h * q_bar) * p
    if f <= 0.0:
        return t_tr, 0.0, q_bar
    lam = f / c_T
    return np.sign(t_tr) * (mu0 + h * (q_bar + lam)) * p, lam, q_bar + lam
