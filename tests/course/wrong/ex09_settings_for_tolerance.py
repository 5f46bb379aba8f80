# Ten times the paper's step: cheap, but the impact is resolved by three steps.
# expect: past their thresholds
def settings_for(tol):
    return {"dt": 1.0, "c_N": 50.0}
