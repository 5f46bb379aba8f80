"""Bodies: the bulk mechanics, assembled with scikit-fem.

Every body offers the same small interface, so that a scene can swap a beam ring
for a continuum ring and the solver never knows the difference:

    body.name          str
    body.X             (nn, 2) reference positions of the nodes that can touch
                       (continuum: mesh nodes; beam: centreline nodes)
    body.ndof          int, number of unknowns of this body
    body.xdofs         (nn, 2) int, local dof numbers of each node's (u_x, u_y)
    body.mass()        (ndof,) lumped (diagonal) mass; body.mass(consistent=True): the
                       consistent mass, a scipy sparse matrix; body.mass_matrix says which
                       the solver uses ("lumped" or "consistent")
    body.internal(u, dt, state) -> (R, K): internal force vector R(u) (ndof,) and its
                       consistent tangent K = dR/du (scipy.sparse, ndof x ndof), with the
                       body's internal variables ``state`` (None for an elastic body)
    body.strain_energy(u, dt, state) -> float
    body.start(u)      the internal variables at the initial state (None if elastic)
    body.commit(u, dt, state) -> the internal variables after u converged (the body
                       keeps nothing: the System carries them in its SystemState)
    body.rotation_dofs local dofs that are angles (a beam's theta; none for a continuum)
    body.discrete_gradient(u0, u1) -> (F, rows, cols, vals): the internal force of an
                       energy-consistent step and its tangent (discrete_gradient.py)

(interfaces.py writes the interface down as a Protocol).

`u` is always the body's own (local) displacement vector; the solver's System
places bodies one after another in the global vector and keeps where each starts
(``System.offset(body)``); a body holds no place of its own.
"""
