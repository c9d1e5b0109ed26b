"""BEM validation runs that write their folders: one design (:func:`validate`,
:func:`write_result`) or a sweep of many (:func:`validate_many`) on local processes, a Dask
cluster or an executor, with their results, fields and figures."""
