# dp/dg_N taken as +dt_N/dg_N: c_N^s has the wrong sign.
# expect: c_N\^s .*the sign is wrong
def slip_moduli(t_tr, c_T, Y_p, Y_q, dtN_dgN):
    D = c_T + Y_q
    return c_T * Y_q / D, np.sign(t_tr) * Y_p * dtN_dgN * c_T / D
