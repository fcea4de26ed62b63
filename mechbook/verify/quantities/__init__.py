"""The answer quantities, one module per family: each module declares its checks on its own
`FAMILY` (mechbook.verify.registration); importing this package declares nothing anywhere
else. The built-in table is built from the modules mechbook.verify.registry lists: a new
family is a new module here and its line in registry.MODULES."""
