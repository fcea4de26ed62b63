"""The application on top: checking problems in batches, the HDF5 store, the command line.

    service      one check of many problems: ids resolved once, the store's valid outcomes,
                 the longest first on the pool or the cluster, each written at once
    run          checking one problem (what a worker does), plain data out
    batch        a pool of worker processes with time and memory limits (any task)
    simrun       `mechbook simulate` in a worker, under the same limits
    distributed  the same on a Dask cluster (--scheduler), limits kept in the workers
    sweep/       `mechbook sweep`: a result over a grid of parameters (runner: the grid
                 evaluated in blocks; precision: float64 against 30 digits; book_answer: the
                 book's answer on the grid; storage: store and netCDF; figures; text_summary:
                 what it prints; spec: a sweep's definition, without NumPy)
    store/       the HDF5 store (writer: written atomically under a lock; reader: reading;
                 warm_cache: the warm-run cache; repair: a damaged store rebuilt; entries,
                 bounds, compaction, child_read)
    fingerprint  content hashes for the warm-run cache
    validate     `mechbook validate`
    limits       the batch's default limits (light: the command line's --help shows them)
    cli/         the `mechbook` command: the entry (group `main`), common options, one
                 module per command (imports the engine only inside commands)
    api          the Python API: mechbook.load(id) -> derived results as SymPy objects
    mathml       SymPy expressions as MathML (the report, notebooks)
    formats      check results as JSON (schemas/check-result.json) and JUnit XML
    frames       the store as pandas DataFrames: mechbook.results(path)
    report/      `mechbook report`: the static HTML report

May import: everything in mechbook.
"""
