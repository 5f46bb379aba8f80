# The return always to +mu p, whatever the direction of the trial traction.
# expect: along sign\(t_tr\)
def coulomb_return(t_bar, dg_T, p, c_T, mu):
    t_tr = t_bar + c_T * dg_T
    f_tr = abs(t_tr) - mu * p
    if f_tr <= 0.0:
        return t_tr, 0.0
    return mu * p, f_tr / c_T
