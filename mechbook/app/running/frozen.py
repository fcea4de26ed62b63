"""Imported last by the batch's fork server (mechbook.app.running.batch): what the server imported
before, the engine, is frozen out of the garbage collector's reach there, once, so every
worker forked from it starts settled instead of collecting and freezing it again (~0.1 s
each). A module only for that import: nothing else imports it."""

from mechbook.app.running.batch import settle

settle()
