# Richardson's value on the wrong side of the finest level: f1 + delta.
# expect: f1 \+ delta
def band_from_three(f1, f2, f3, r, p_th):
    e21, e32 = f2 - f1, f3 - f2
    p = np.log(e32 / e21) / np.log(r)
    delta = e21 / (r**p - 1.0)
    P = p / p_th
    fs = 1.6 * P + 2.45 * (1.0 - P) if P <= 1.0 else 1.6 * P + 2.45 * (P - 1.0)
    return p, f1 + delta, fs * abs(delta)
