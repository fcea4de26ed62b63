"""Default limits of a batch of checks (a module of its own so that the command line can show
them in --help without importing the batch machinery, h5py and NumPy)."""

DEFAULT_TIMEOUT = 600.0  # seconds per problem; the slowest takes well under a minute
DEFAULT_MEMORY_MB = 8000  # resident memory per worker
