"""What a problem is, the framework every scene is written in: named parameters with units
and ranges (params.py), a scene's description and the one ``run`` of them all (scene.py), the
model a scene builds and the stage it marches (model.py), a scene file a user writes
(files.py), the size of a run before it runs (resources.py), the contact's enforcement and the
time integration a scene chooses by its parameters (enforcement.py, time_integration.py), and
how accurate a run is (accuracy.py). The scenes themselves are in ``contactfem.scenes``."""
