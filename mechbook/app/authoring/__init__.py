"""The author's loop: a tree of one's own started, a problem and its key written, checked as
they are saved, with an editor that knows the schemas.

    init      `mechbook init`: the starter tree (starter/, shipped in the package) written
    validate  `mechbook validate`: a problem and its key read and built, nothing checked, the
              build bounded in CPU time
    watch     `mechbook watch`: a problem checked again each time its files are saved
    editor    the JSON Schemas written for an editor's YAML language server

Import each part from its module (`from mechbook.app.authoring.validate import ...`): this
`__init__` imports nothing, since the command line loads each part only when its command
runs.

May import: the stages below mechbook.app, its shared modules, store/, running/ (watch's
worker, the check) and output/ (the table, safe text, the check's schema).
"""
