"""The application on top: checking problems in batches, the HDF5 store, the command line.

    run          checking one problem (what a worker does), plain data out
    batch        a pool of worker processes with time and memory limits (any task)
    simrun       `mechbook simulate` in a worker, under the same limits
    store        the HDF5 store, written atomically under a lock
    fingerprint  content hashes for the warm-run cache
    validate     `mechbook validate`
    cli          the `mechbook` command (imports the engine only inside commands)

May import: everything in mechbook.
"""
