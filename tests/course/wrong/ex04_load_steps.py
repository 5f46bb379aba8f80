# The nodes in contact counted instead of the slipping ones.
# expect: nodes in contact, not the slipping ones
from contactfem.solver import Steps, march


def load_steps(stepper, n):
    times, solves, slipping = [], [], []
    for rec in march(stepper, Steps(1.0 / n, n_steps=n), 0.0, np.zeros(stepper.system.ndof)):
        if rec.k == 0:
            continue
        times.append(rec.t)
        solves.append(rec.iterations)
        slipping.append(rec.contacts[0].n_active)
    return times, solves, slipping
