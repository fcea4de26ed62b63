"""The application on top: the command line, the Python API, the author's loop, checks run in
batches, the HDF5 store, the report. One package per part, each importing only those below
it (bottom up; tests/test_architecture.py's APP_PACKAGES):

    output/     text out: strings made safe for each output, the console's progress and
                table, JSON and JUnit, MathML and its line breaks
    store/      the HDF5 store (its `__init__` the public door), the side file of results
                it could not take (unsaved) and `restore`
    running/    one check (run), many (service) on a pool with limits (batch) or a Dask
                cluster (distributed), `simulate` in a worker (simrun), the fork server's
                first and last imports (forkstart, frozen), lifeline, quiet
    sweep/      `mechbook sweep`: a result over a grid of parameters
    report/     `mechbook report`: the static HTML report
    authoring/  the author's loop: init (and the starter/ tree), validate, watch, editor
                (running/ reads validate: every check starts with its bounded build)
    api/        the Python API: mechbook.load(id) -> derived results as SymPy objects,
                mechbook.results(path) -> the store as DataFrames
    cli/        the `mechbook` command: the entry (group `main`), one module per command
                (imports the engine only inside commands)

Shared by several of them, flat: options (bounded numeric options, a batch's default
limits), outputs (where results may be written), bounded (files read back within bounds),
selection (which problems a command means), fingerprint (the warm-run cache's hashes), docs
(the documentation pages); schemas/ holds the check result's JSON Schema.

May import: everything in mechbook.
"""
