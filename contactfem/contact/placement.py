"""Where an object's unknowns start in a System's global vector: a body's dofs, a contact's
own unknowns (Lagrange multipliers). The System keeps these offsets (``System.offsets``, by
the object's identity) and hands them to the contacts and loads it evaluates; bodies and
contacts hold configuration only, never a place written on them from outside.

Used without a System (a test, a lecture's single body), an object starts at its own
``dof_offset`` where its configuration names one (a test's point cloud placed after another),
else at 0."""


def start_of(obj, offsets=None):
    """The global index where ``obj``'s unknowns start: ``offsets[id(obj)]`` (a System's), else
    the object's configured ``dof_offset``, else 0."""
    if offsets is not None:
        return offsets[id(obj)]
    return getattr(obj, "dof_offset", None) or 0


def placed(obj, offsets=None):
    """Whether ``obj``'s place is known: a System's ``offsets``, or its own configured one."""
    return offsets is not None or getattr(obj, "dof_offset", None) is not None
