"""The designer: a target to a checked, printable design (:func:`design`, :func:`compare`),
what it returns (:class:`DesignResult`, :class:`Curve`), and what to do with a design you
have (curve, export, physical, pressure_check, view, the scale search)."""
