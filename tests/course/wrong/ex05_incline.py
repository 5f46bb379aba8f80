# The friction law left out: the ring slides down without friction.
# expect: sliding without friction
from contactfem.bodies.ring import make_ring
from contactfem.contact import NodeToSegment, RigidLine
from contactfem.laws import PowerLaw
from contactfem.scenes import get_scene
from contactfem.solver import Newmark, Steps, System, march


def ring_on_incline(theta_deg, mu, t_end=0.5):
    P = get_scene("rolling_ring").resolve("fast")
    th = np.radians(theta_deg)
    n = np.array([-np.sin(th), np.cos(th)])
    R, h = P["R"], P["thickness"]
    ring = make_ring(
        kind="beam",
        R=R,
        thickness=h,
        width=P["width"],
        n_el=P["n_el"],
        E=P["E"],
        nu=P["nu"],
        rho=P["rho"],
        center=(R + h / 2) * n,
    )
    contact = NodeToSegment(
        ring.body,
        ring.contact_nodes,
        RigidLine((0.0, 0.0), n),
        normal=PowerLaw(P["c_N"], 1.0),
        friction=None,
        offset=ring.offset,
    )
    system = System([ring.body], [contact], [ring.gravity(P["g"])])
    stepper = Newmark(system, P["delta"], P["beta_newmark"], atol=1e-6, rtol=1e-10, maxit=30)
    down = np.array([-np.cos(th), -np.sin(th)])
    x0 = ring.center_of_mass(np.zeros(ring.body.ndof))
    t, s = [], []
    for rec in march(stepper, Steps(P["dt"], t_end=t_end, max_cuts=8), 0.0, np.zeros(ring.body.ndof)):
        t.append(rec.t)
        s.append((ring.center_of_mass(rec.u) - x0) @ down)
    return np.array(t), np.array(s)
