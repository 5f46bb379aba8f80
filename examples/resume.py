from contactfem.io import load_record, save_record
from contactfem.scenes import get_scene
from contactfem.problem.scene import simulate
from contactfem.solver.march import resume

scene = get_scene("sloping_impact")
params = scene.resolve("fast", {"variant": "frictional"})
model = scene.build(params)
records = simulate(model, params)  # the whole run
save_record(records[10], "step10.npz")  # one record, with its SystemState
stage = model.stage
rest = list(resume(stage.stepper, stage.schedule, load_record("step10.npz")))  # = records[11:]
