# The geometric part of eq (33) forgotten.
# expect: geometric part .* is missing
from contactfem.contact.kinematics import outer, segment_geometry, segment_vectors


def normal_tangent(x_s, x_1, x_2, c_N):
    l, t, n, g_N, alpha = segment_geometry(x_s[None], x_1[None], x_2[None])
    N_s = segment_vectors(t, n, alpha)[0]
    return c_N * outer(N_s, N_s)[0]
