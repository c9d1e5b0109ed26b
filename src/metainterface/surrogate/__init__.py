"""The surrogate: the inverse MLP (curve -> design), trained through the physics layer.

``model`` (the network), ``loss`` (the composite loss), ``schedules`` (curriculum lambda and
kappa_s annealing), ``train`` (the resumable training loop), ``checkpoint`` (model files,
loaded with ``weights_only=True``), ``evaluate`` (zero-shot errors per category). The public
entry points are ``metainterface.train_surrogate`` and ``metainterface.evaluate_surrogate``.
"""
