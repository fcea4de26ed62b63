"""`mechbook report`: a static HTML report of the store, readable offline in any browser.

    build      the index and one page per problem (pages computed on worker processes)
    page       one problem's page: the derivation as MathML, book and engine side by side
    values     the book's value and the engine's counterpart of an answer part
    svg        the charts (inline SVG); animation the bodies' motion as frames for a canvas
    templates/ the pages (Jinja2, autoescaped); assets/ the style sheet and the filter script

Mathematics is SymPy's presentation MathML (mechbook.app.output.mathml), which browsers render
natively: the report needs no script from elsewhere and no network.

May import: the stages below mechbook.app, its shared modules, store/, running/ and
output/ (MathML, safe text).
"""
