"""Self-contained HTML pages: the diagnosis report, the fits and the paper's tables.

Each page is one file: styles inline, figures embedded as SVG data URIs, nothing fetched
from elsewhere; it reads on a laptop and on a phone. The diagnosis page renders from
:meth:`lugre.diagnosis.Diagnosis.to_dict` and the diagnosis's ``data`` arrays, and uses
the optional keys when present (``verdict``, per finding ``uncertainty``,
``could_not_reveal``, ``base_moves``, ``unexplained``, ``notes``, ``data["effects"]``).
"""

from __future__ import annotations

from ._words import plain_text
from .pages.diagnosis import EXPERIMENTS, diagnosis_page
from .pages.fit import fit_page, static_fit_page
from .pages.paper import paper_document, paper_page

__all__ = ["EXPERIMENTS", "diagnosis_page", "fit_page", "paper_document", "paper_page",
           "plain_text", "static_fit_page"]
