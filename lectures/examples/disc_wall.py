"""A scene file: a disc (the Gmsh mesh disc.msh, read through meshio) thrown against a polyline wall."""

from pathlib import Path
import numpy as np
from skfem import MeshTri
from contactfem.bodies.continuum import Continuum
from contactfem.contact import NodeToSegment, RigidPolyline
from contactfem.laws import Coulomb, PowerLaw
from contactfem.scenes import Model, Param, Quantity, Scene, Stage, time_step
from contactfem.solver import History, Newmark, Steps, System

WALL = [(-3.0, 0.0), (1.0, 0.0), (4.0, 2.0)]  # left to right: the disc is on the wall's left side
R = 1.0  # the disc's radius in disc.msh
PARAMS = (
    Param("v0", 2.0, "length/time", 0.0, 20.0, doc="speed of the throw, 45 degrees down"),
    Param("mu", 0.3, "", 0.0, 2.0, doc="Coulomb friction coefficient (friction law)"),
    Param("c_N", 1e3, "force/length", 0.0, 1e8, True, doc="normal penalty, per node (normal law)"),
    Param("c_T", 1e3, "force/length", 0.0, 1e8, True, doc="stick stiffness, per node (friction law)"),
    Param("dt", 0.01, "time", 0.0, 0.1, True, doc="time step"),
    Param("n_steps", 150, "", 1, 10_000, doc="number of steps"),
)


def build(p, *, normal=None, friction=None, system_options=None):
    disc = Continuum(
        MeshTri.load(str(Path(__file__).with_name("disc.msh"))), E=100.0, nu=0.3, rho=1.0, material="svk", name="disc"
    )
    contact = NodeToSegment(
        disc,
        disc.mesh.boundary_nodes(),
        RigidPolyline(WALL),
        name="wall",
        normal=normal or PowerLaw(p["c_N"]),
        friction=friction or Coulomb(p["c_T"], p["mu"]),
    )
    system = System([disc], [contact], **(system_options or {}))
    v0 = np.zeros(disc.ndof)
    v0[disc.xdofs] = p["v0"] * np.array([0.5**0.5, -(0.5**0.5)])
    steps = Steps(p["dt"], n_steps=p["n_steps"], max_cuts=4)  # a step Newton fails is halved, up to 4 times
    ends = disc.mesh.p[:, disc.mesh.facets[:, disc.mesh.boundary_facets()]]  # the surface's edges: (x|y, end, edge)
    sizes = dict(element=float(np.hypot(*(ends[:, 1] - ends[:, 0])).max()), body=2 * R)  # the penetration's yardsticks
    # full Newton steps cycle between two iterates here at dt / 2 (a non-smooth contact): backtrack, 4 halvings
    stage = Stage(Newmark(system, 0.5, 0.25, line_search=4), steps, np.zeros(disc.ndof), v0)
    return Model(systems=(system,), stage=stage, sizes=sizes, parts=dict(disc=disc))


def measure(model, p, records):
    disc, hist = model.parts["disc"], History.of(records)
    m = disc.mass()[disc.xdofs[:, 0]]  # lumped nodal masses
    vx, vy = m @ hist.v[disc.xdofs] / m.sum()  # the centre of mass's final velocity (History's v: the last)
    return dict(rebound_vx=float(vx), rebound_vy=float(vy), energy_kinetic=hist.kinetic)


def law_range(p):  # what the laws meet: a node's spring pressed a radius deep; slip and slip rate of a spinning disc
    return dict(p=p["c_N"] * R, q=3 * p["v0"] * p["n_steps"] * p["dt"], v=3 * p["v0"], dt=p["dt"], g=R)


SCENE = Scene(
    "disc_wall",
    "A disc thrown against a polyline wall",
    PARAMS,
    build,
    measure,
    laws=("normal", "friction"),
    law_params={"normal": ("c_N",), "friction": ("c_T", "mu")},
    law_range=law_range,
    quantities=(Quantity("rebound_vx", "length/time"), Quantity("rebound_vy", "length/time")),  # error bars in dt
    discretisations=(time_step("dt", count="n_steps"),),
)
