"""The reproduction report: run the thesis's cases and compare them with its tables.

:func:`reproduce` runs the chapters asked for, writes ``README.md`` (the report, Markdown)
and its PNG figures under ``figures/`` in an output directory, and returns the path of the
report. The command line ``granrs reproduce --out DIR`` calls it (see :mod:`granrs.cli`).

Chapters form a registry (:data:`CHAPTERS`): a chapter is a function that takes a
:class:`ReportContext`, runs its simulations through it, adds its figures and headline
numbers to it, and returns its Markdown text. :func:`register_chapter` adds one; the free
link (chapter 3), the chain (chapter 4), the leg (chapter 5), the calibration chapter, the
force laws (:mod:`~granrs.report.force_laws`) and "Which law fits the experiments"
(:mod:`~granrs.report.laws`, which also writes ``laws.json``) register themselves when this
package imports their modules, in that order.

The package by concern: :mod:`~granrs.report.framework` (the registry, the context, writing
the report), :mod:`~granrs.report.format` (numbers and Markdown), one module per chapter
(:mod:`~granrs.report.ch3_free_link`, :mod:`~granrs.report.ch4_chain`,
:mod:`~granrs.report.ch5_leg`, :mod:`~granrs.report.calibration`). The framework never
imports a chapter; this package does, so that importing :mod:`granrs.report` registers them.

Chapter 3 (the free link) compares granrs with:

* Table 3.1 (the experiments: mean and sd of five drops), with Table 3.4 coefficients and
  the force applied at the tip, as the thesis's CAD runs did (sec. 3.3.2);
* Table 3.5 (the thesis's own simulation), every row, with the relative error of eq. 3.21;
  and the same with the Table 3.2 closed-form coefficients;
* Tables 3.6 (forces) and 3.7 (energies) at the speeds of sec. 3.4 (``sweep_3_4``);
* Figs. 3.15-3.20 (depth and tip velocity against time) and 3.22-3.23 (depth and stopping
  time against the impact angle alpha).

Chapter 4 (the two-link chain) compares granrs with Table 4.2 (the experiments) per link at
two link masses (the thesis does not give it: solid steel, 0.0341 kg, and half of it), with
Tables 4.5-4.6 (the thesis's simulation and its errors), sweeps the link mass for the best
fit to the measured depths, asks whether the links stop together, sets the forces and
energies quoted in sec. 4.3 beside granrs's, and draws Figs. 4.7-4.16 and the pin force.

Chapter 5 (the leg) compares granrs with Table 5.1 (per subject and height, and the mean)
and the thesis's simulation (sec. 5.3.2), then runs a joint study (locked, free,
spring-dampers over a sweep of stiffness, the thesis's sole) to show which settings come
closest to the thesis and to the experiments, and draws Fig. 5.10.

Relative errors follow the thesis's eq. 3.21, epsilon = |reference - granrs| / |reference|,
the reference being the experiment or the thesis's table. Every granrs number in the report
is computed at run time; nothing is edited to fit. Reference numbers come from the shipped
tables (:mod:`granrs.data`), except the few the thesis gives only in its text (secs. 4.2.2,
4.3 and 5.2.2), which are constants here citing their section.

Writing is all-or-nothing: every simulation and figure is produced in memory first, then
the files are written to a temporary directory next to the output directory and moved into
place, so an error leaves no half-written report.
"""

from __future__ import annotations

# The chapters register themselves on import; the order of these imports is the order of
# the report (3, 4, 5, calibration, force_laws, laws), so it is kept out of the import sorting.
# isort: off
from . import ch3_free_link as ch3_free_link
from . import ch4_chain as ch4_chain
from . import ch5_leg as ch5_leg
from . import calibration as calibration
from . import force_laws as force_laws
from . import laws as laws

# isort: on
from .ch3_free_link import chapter_3 as chapter_3
from .ch4_chain import _MASS_SWEEP as _MASS_SWEEP
from .ch4_chain import chapter_4 as chapter_4
from .ch5_leg import _LEG_STIFFNESS as _LEG_STIFFNESS
from .ch5_leg import chapter_5 as chapter_5
from .format import md_table as md_table
from .format import relative_error
from .framework import (
    CHAPTERS,
    Chapter,
    ChapterBuilder,
    ReportContext,
    register_chapter,
    reproduce,
)
from .framework import (
    FIGURES_DIR as FIGURES_DIR,
)
from .framework import (
    REPORT_NAME as REPORT_NAME,
)

__all__ = [
    "CHAPTERS",
    "Chapter",
    "ChapterBuilder",
    "ReportContext",
    "register_chapter",
    "relative_error",
    "reproduce",
]
