# The angle measured from the plane, not from its normal.
# expect: measured from the plane
def rebound(v_c, in_contact):
    v_c, in_contact = np.asarray(v_c, dtype=float), np.asarray(in_contact, dtype=bool)
    touched = np.flatnonzero(in_contact)
    if touched.size == 0 or touched[-1] == len(in_contact) - 1:
        return None, None, None
    vx, vy = v_c[touched[-1] + 1]
    return vx, vy, float(np.degrees(np.arctan2(abs(vy), abs(vx))))
