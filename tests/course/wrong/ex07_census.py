# The slipping nodes counted as the nodes in contact.
# expect: slipping nodes: a node is in contact
from contactfem.laws.return_map import SLIP
from contactfem.solver import march


def census(stepper, schedule, u0, v0):
    t, n_contact, n_slip = [], [], []
    for rec in march(stepper, schedule, 0.0, u0, v0):
        slip = int(np.count_nonzero(rec.contacts[0].slip == SLIP))
        t.append(rec.t)
        n_contact.append(slip)
        n_slip.append(slip)
    return np.array(t), np.array(n_contact), np.array(n_slip)
