"""The HDF5 store: every run's results, checks and provenance (the layout and how a write is
made atomic: mechbook.app.store.writer). Import the store from here; the modules inside are
its parts:

    writer       problems and simulations written atomically under a lock
    reader       a problem's record, a simulation, the list of problems; StoreError
    entries      a record read whole and checked to be what mechbook writes; `damage`
    bounds       everything read from a store bounded before it is read
    warm_cache   which stored outcomes are still valid; each problem's last duration
    repair       a damaged store found before an edit, moved aside and rebuilt
    compaction   a store written anew with only what it holds
    child_read   a store not yet found sound read in a child under a CPU limit
    unsaved      results the store could not take, kept in a side file (import it from
                 its module: it is not loaded with the store)
    restore      `mechbook restore`: a side file read back, checked, written into a store

May import: the stages below mechbook.app, its shared modules (outputs, bounded,
fingerprint) and output/'s text (strings made safe for HDF5 and JSON); never the command
line, the running of checks or the report.
"""

from mechbook.app.store.bounds import attributes, member
from mechbook.app.store.entries import FORMAT, damage, read_sweep_entry, reason_of, refusal
from mechbook.app.store.reader import (
    DEFAULT_PATH,
    StoreError,
    StoreHang,
    hang_reason,
    names_in,
    opened,
    problems,
    read,
    read_simulation,
    regular_store,
    there,
    vet,
)
from mechbook.app.store.repair import DAMAGED
from mechbook.app.store.warm_cache import Cached, cached, durations
from mechbook.app.store.writer import (
    ProblemRecord,
    atomic_edit,
    attribute_value,
    bounded_text,
    check_run_name,
    compact_store,
    write,
    write_simulation,
)

__all__ = [
    # writing
    "ProblemRecord", "write", "write_simulation", "compact_store", "check_run_name",
    # reading
    "DEFAULT_PATH", "FORMAT", "StoreError", "StoreHang", "hang_reason", "read",
    "read_simulation", "problems", "regular_store", "vet", "there", "damage", "refusal", "DAMAGED",
    # the warm-run cache
    "Cached", "cached", "durations",
    # for the store's other entries (a sweep's: mechbook.app.sweep.storage)
    "atomic_edit", "attribute_value", "bounded_text", "opened", "names_in", "reason_of",
    "read_sweep_entry",
    "attributes", "member",
]
