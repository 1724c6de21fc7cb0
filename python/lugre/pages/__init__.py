"""The one-file HTML pages, one module a page; :mod:`lugre.html` gathers them."""
