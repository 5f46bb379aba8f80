"""Export a run to ParaView: one VTU file per snapshot plus a .pvd collection that
ParaView opens as a time series (File > Open > run.pvd, then press play).

    export_continuum(body, rec.t, rec.u, "out/block.pvd")          # a Continuum's mesh
    export_polyline([beam.positions(u) for u in rec.u], rec.t, "out/ring.pvd", closed=True)
    export_series(points, cells, times, "out/any.pvd", point_data=...)   # anything else

The VTU files are written with meshio (https://github.com/nschloe/meshio), an
optional dependency: ``pip install meshio``. The .pvd file is a few lines of XML
written here.
"""

from pathlib import Path

import numpy as np

from .. import lazy

saxutils = lazy.module("xml.sax.saxutils")  # (pulls in urllib: ~0.1 s, only when writing)


def _meshio():
    try:
        import meshio  # optional extra (io): may be absent
    except ImportError:
        raise ImportError("export to ParaView needs the optional package meshio: pip install meshio") from None
    return meshio


def _pad3(x):
    """(n, 2) positions -> (n, 3) with z = 0 (ParaView works in 3D)."""
    x = np.asarray(x, dtype=float)
    if x.ndim != 2 or x.shape[1] not in (2, 3):
        raise ValueError(f"parameter points must be (n, 2) or (n, 3) per snapshot, got shape {x.shape}")
    return np.column_stack([x, np.zeros(len(x))]) if x.shape[1] == 2 else x


def write_pvd(path, files, times):
    """The ParaView collection: one <DataSet timestep=...> per file (paths relative to the .pvd)."""
    path = Path(path)
    rows = "\n".join(
        f'    <DataSet timestep="{float(t)!r}" part="0" file={saxutils.quoteattr(Path(f).name)}/>'
        for f, t in zip(files, times)
    )
    path.write_text(
        '<?xml version="1.0"?>\n<VTKFile type="Collection" version="0.1">\n  <Collection>\n'
        f"{rows}\n  </Collection>\n</VTKFile>\n"
    )
    return str(path)


def export_series(points, cells, times, path, point_data=None, cell_data=None):
    """Write a time series of one mesh whose nodes move.

    points     : sequence of (n, 2|3) node positions, one per snapshot
    cells      : list of (cell_type, connectivity) in meshio's names: "line", "triangle", "quad"
    times      : one time per snapshot
    point_data : dict name -> sequence of per-snapshot arrays (n,) or (n, k)
    cell_data  : dict name -> sequence of per-snapshot arrays, one value per cell (single cell block)
    path       : the .pvd file; the VTU files go next to it as <stem>_0000.vtu, ...

    Returns the list of files written (the .pvd last)."""
    meshio = _meshio()
    path = Path(path)
    if path.suffix != ".pvd":
        raise ValueError(f"parameter path must end in .pvd, got {path.name!r}")
    points = list(points)
    times = np.asarray(times, dtype=float).ravel()
    if len(points) != len(times) or len(points) == 0:
        raise ValueError(
            f"parameter times must give one time per snapshot: {len(times)} times, {len(points)} snapshots"
        )
    point_data = point_data or {}
    cell_data = cell_data or {}
    for name, series in list(point_data.items()) + list(cell_data.items()):
        if len(series) != len(points):
            raise ValueError(f"data {name!r} has {len(series)} snapshots, expected {len(points)}")
    path.parent.mkdir(parents=True, exist_ok=True)
    files = []
    for k, x in enumerate(points):
        mesh = meshio.Mesh(
            _pad3(x),
            cells,
            point_data={n: np.asarray(s[k], dtype=float) for n, s in point_data.items()},
            cell_data={n: [np.asarray(s[k], dtype=float)] for n, s in cell_data.items()},
        )
        f = path.with_name(f"{path.stem}_{k:04d}.vtu")
        meshio.write(f, mesh)
        files.append(str(f))
    return files + [write_pvd(path, files, times)]


def export_continuum(body, times, us, path, stress=True):
    """Time series of a Continuum body (contactfem.bodies.continuum): deformed mesh, the
    displacement as point data and, if `stress`, the Cauchy stress at the element centres
    (components sxx, syy, sxy, szz and the von Mises stress) as cell data.
    `us` are the body's own displacement vectors (its local dofs)."""
    mesh = body.mesh
    kind = {3: "triangle", 4: "quad"}[mesh.t.shape[0]]
    cells = [(kind, mesh.t.T.astype(int))]
    us = [np.asarray(u, dtype=float) for u in us]
    disp = [u[body.xdofs] for u in us]
    points = [body.X + d for d in disp]
    cell_data = {}
    if stress:
        sig = [body.cauchy_stress(u) for u in us]
        for name, (i, j) in dict(sxx=(0, 0), syy=(1, 1), sxy=(0, 1), szz=(2, 2)).items():
            cell_data[name] = [s[:, i, j] for s in sig]
        cell_data["von_mises"] = [von_mises(s) for s in sig]
    return export_series(points, cells, times, path, point_data={"displacement": disp}, cell_data=cell_data)


def von_mises(sigma):
    """Von Mises stress sqrt(3/2 s:s), s the deviator of the 3x3 stresses sigma (n, 3, 3)."""
    s = sigma - np.trace(sigma, axis1=1, axis2=2)[:, None, None] * np.eye(3) / 3.0
    return np.sqrt(1.5 * np.einsum("kij,kij->k", s, s))


def export_polyline(frames, times, path, closed=False, point_data=None):
    """Time series of a chain of nodes (a beam's centreline, a ring, a contact surface):
    frames is a sequence of (n, 2) positions; closed joins the last node to the first."""
    frames = [np.asarray(x, dtype=float) for x in frames]
    n = len(frames[0]) if frames else 0
    if n < 2:
        raise ValueError("parameter frames must hold polylines of at least 2 points")
    seg = np.column_stack([np.arange(n - 1), np.arange(1, n)])
    if closed:
        seg = np.vstack([seg, [n - 1, 0]])
    return export_series(frames, [("line", seg)], times, path, point_data=point_data)
