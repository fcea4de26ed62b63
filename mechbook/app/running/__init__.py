"""Running checks: one problem in a worker, many on a pool of workers or a Dask cluster,
within time and memory limits, each result written as it ends.

    service      one check of many problems: ids resolved once, the store's valid outcomes,
                 the longest first on the pool or the cluster, each written at once
    run          checking one problem (what a worker does), plain data out
    batch        a pool of worker processes with time and memory limits (any task)
    simrun       `mechbook simulate` in a worker, under the same limits
    distributed  the same on a Dask cluster (--scheduler), limits kept in the workers
    lifeline     a worker dies with the run that started it, even one killed with -9
    serverstart  the fork server started with Ctrl-C, SIGTERM and SIGHUP held
    forkstart    imported first by the fork server: Ctrl-C ignored, its folder removed
    frozen       imported last by the fork server: what it imported frozen out of the GC
    quiet        warnings and stray tracebacks become notes

Import each part from its module (`from mechbook.app.running.batch import Batch`): this
`__init__` imports nothing, because the fork server imports forkstart through it before
anything else, and the command line's start-up must stay light.

May import: the stages below mechbook.app, its shared modules, store/, output/ (the check's
formats, safe text) and authoring's validate (the bounded build every check starts with);
never the command line, the API or the report.
"""
