"""Local + global approximated dependent multi-output GP for the aerodynamic coefficients.

Global layer: a sparse variational (VFE) GP with inducing points and an intrinsic
coregionalisation model (outputs coupled through ``B``), on top of a Bayesian linear
mean in the regressors (the stability-and-control-derivative model). Local layer:
nearest-neighbour GPs with a non-stationary (Paciorek-Schervish) covariance on the
global residual. Inducing points by greedy mutual information. See ``docs/gp.md``.

Public API::

    model, history = fit_gp(X, Y, GPConfig())
    mean, var = model.predict(X)              # (N, P), (N, P)
    mean_g, var_g = model.predict_global(X)
    model = model.update(X_new, Y_new)        # streaming, bounded memory (inducing exchange, capped row store)
    model = model.refresh_hyperparameters()   # on request, or every GPConfig.hyper_every rows
    var_after = model.variance_after(X_extra, X_query)
    pairs = model.global_variance_after_many(X_extras, X_queries)   # batched, for ranking
    model.save("dir/gp"); model = load_gp("dir/gp")
"""

from .config import GPConfig
from .fit import FitHistory, fit_gp
from .io import load_gp
from .model import LocalGlobalGP

__all__ = ["GPConfig", "FitHistory", "LocalGlobalGP", "fit_gp", "load_gp"]
