"""A4 page layout on matplotlib: headings, paragraphs, figures and tables flowed onto pages.

:class:`Layout` keeps every page as a :class:`matplotlib.figure.Figure` until :meth:`Layout.save`
writes them with :class:`~matplotlib.backends.backend_pdf.PdfPages` (running header, page numbers,
PDF metadata). Figures are embedded as images at :data:`DPI`; captions and tables are text, so the
PDF is searchable. Nothing here knows what a result file contains (that is :mod:`.sections`).
"""

from __future__ import annotations

import contextlib
import logging
import multiprocessing
import textwrap
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field

import matplotlib
import numpy as np
import pandas as pd
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.backends.backend_pdf import PdfPages
from matplotlib.figure import Figure
from matplotlib.lines import Line2D
from matplotlib.text import Text

from microimpact.io.files import atomic_path
from microimpact.io.formatting import format_cell

__all__ = ["PAGE_SIZE", "DPI", "Layout", "Page", "fork_map", "render_figures", "wrap"]

#: A4 portrait [in]
PAGE_SIZE = (8.27, 11.69)
#: resolution of the embedded figures [dots per inch]
DPI = 160
MARGIN_X = 0.65  # in
TOP = 0.75  # in, below the top edge: running header
BOTTOM = 0.75  # in, above the bottom edge: footer
FOOTNOTE_Y = 0.9  # in, above the bottom edge: the title page's footnote
TEXT_WIDTH = PAGE_SIZE[0] - 2 * MARGIN_X
BODY_PT = 8.5
TABLE_PT = 6.6
SOURCE_COLOR = "#1f4e8c"


def wrap(text: str, width: int) -> list[str]:
    """``text`` wrapped to ``width`` characters, its own line breaks kept.

    Examples
    --------
    >>> wrap("one two three\\nfour", 8)
    ['one two', 'three', 'four']
    """
    lines: list[str] = []
    for para in str(text).split("\n"):
        lines.extend(textwrap.wrap(para, width=width, break_long_words=True, break_on_hyphens=False) or [""])
    return lines


def _chars_per_line(size: float, mono: bool = False) -> int:
    return int(TEXT_WIDTH * 72 / (size * (0.61 if mono else 0.53)))


@dataclass
class Page:
    """One A4 page: its figure, the section named in its header, the next free line [in from the top].

    Examples
    --------
    >>> from matplotlib.figure import Figure
    >>> p = Page(Figure(figsize=PAGE_SIZE), "Fit", 1.0)
    >>> p.section, p.y, p.figure.get_size_inches().round(2).tolist()
    ('Fit', 1.0, [8.27, 11.69])
    """

    figure: Figure
    section: str
    y: float


@dataclass
class Layout:
    """Flows headings, figures, paragraphs and tables onto A4 pages.

    Attributes
    ----------
    title : str
        Running header of every page but the first.
    pages : list of Page
    contents : list of (str, int)
        Section title and the index of its page, for the table of contents.

    Examples
    --------
    Asking for room on an empty layout starts the first page.

    >>> lay = Layout("Report")
    >>> _ = lay.ensure(1.0)
    >>> len(lay.pages), lay.title
    (1, 'Report')
    """

    title: str
    pages: list = field(default_factory=list)
    contents: list = field(default_factory=list)
    _number: int = 0
    _part_start: bool = False  # the next section follows the introduction of a part on its page
    _current: str = ""  # the section being written
    _figures: list = field(default_factory=list)  # (axes on a page, matplotlib figure) drawn at save

    # ------------------------------------------------------------------ pages
    def new_page(self, section: str) -> Page:
        page = Page(Figure(figsize=PAGE_SIZE), section, TOP + 0.15)
        self.pages.append(page)
        return page

    @property
    def page(self) -> Page:
        return self.pages[-1]

    def ensure(self, height: float) -> Page:
        """The current page if ``height`` [in] still fits on it, else a new page of the same section."""
        if not self.pages or self.page.y + height > PAGE_SIZE[1] - BOTTOM:
            self.new_page(self._current)
        return self.page

    def _text(self, x_in: float, y_in: float, text: str, **kw):
        return self.page.figure.text(x_in / PAGE_SIZE[0], 1.0 - y_in / PAGE_SIZE[1], text, va="top", **kw)

    # ------------------------------------------------------------------ blocks
    def part(self, title: str, intro: str) -> None:
        """Start a part of the report on a new page: a large title and an introduction."""
        self._current = title
        self.new_page(title)
        self.contents.append((title, len(self.pages) - 1))
        lines = wrap(title, 52)
        self._text(MARGIN_X, self.page.y, "\n".join(lines), fontsize=15, fontweight="bold", color=SOURCE_COLOR,
                   linespacing=1.2)
        self.page.y += 0.3 * len(lines) + 0.12
        self.paragraph(intro, size=9, gap=0.25)
        self._part_start = True

    def section(self, title: str, *, new_page: bool = True, numbered: bool = True, keep: float = 0.4) -> str:
        """A section heading, numbered in order unless ``numbered`` is False; returns the full title.

        The section starts a new page when ``new_page`` is True, except the first section of a part,
        which follows the part's introduction. Otherwise it moves to the next page unless ``keep``
        [in] of what follows fits below it.
        """
        if numbered:
            self._number += 1
            title = f"{self._number}. {title}"
        self._current = title  # the header of the pages it starts; a page it joins keeps its own
        if (new_page and not self._part_start) or not self.pages:
            self.new_page(title)
        else:
            self.ensure(0.4 + keep)
        self._part_start = False
        self.contents.append((title, len(self.pages) - 1))
        self._text(MARGIN_X, self.page.y, title, fontsize=13, fontweight="bold")
        self.page.y += 0.38
        return title

    @property
    def number(self) -> int:
        """Number of the current section."""
        return self._number

    def heading(self, text: str, *, keep: float = 0.64) -> None:
        """A sub-heading, moved to the next page unless ``keep`` [in] of what follows fits below it."""
        self.ensure(0.26 + keep)
        self._text(MARGIN_X, self.page.y, text, fontsize=10, fontweight="bold")
        self.page.y += 0.26

    def paragraph(self, text: str, *, size: float = BODY_PT, mono: bool = False, gap: float = 0.1,
                  color: str = "black") -> None:
        """Wrapped text, continued on the next page when it does not fit."""
        line_h = size * 1.32 / 72
        lines = wrap(text, _chars_per_line(size, mono))
        while lines:
            self.ensure(line_h * min(len(lines), 2))
            fit = max(1, int((PAGE_SIZE[1] - BOTTOM - self.page.y) / line_h))
            chunk, lines = lines[:fit], lines[fit:]
            self._text(MARGIN_X, self.page.y, "\n".join(chunk), fontsize=size, linespacing=1.32,
                       family="monospace" if mono else "sans-serif", color=color)
            self.page.y += line_h * len(chunk)
        self.page.y += gap

    def source(self, text: str) -> None:
        """The line that says which parameters made the results of a section."""
        self.paragraph(f"Parameters: {text}", size=7.8, color=SOURCE_COLOR, gap=0.12)

    def plot(self, plot, *, max_height: float = 5.2, heading: str | None = None) -> None:
        """A :class:`microimpact.report.figures.Plot`: the figure as an image, its caption below.

        ``heading``, if given, is set above the figure on the same page.
        """
        fig = plot.figure
        w, h = fig.get_size_inches()
        scale = min(1.0, TEXT_WIDTH / w, max_height / h)
        ww, hh = w * scale, h * scale
        cap_lines = len(wrap(plot.caption, _chars_per_line(BODY_PT)))
        self.ensure(hh + 0.1 + cap_lines * BODY_PT * 1.32 / 72 + (0.26 if heading else 0.0))
        if heading:
            self.heading(heading, keep=0.0)
        x0 = MARGIN_X + (TEXT_WIDTH - ww) / 2
        ax = self.page.figure.add_axes([x0 / PAGE_SIZE[0], 1.0 - (self.page.y + hh) / PAGE_SIZE[1],
                                        ww / PAGE_SIZE[0], hh / PAGE_SIZE[1]])
        ax.set_axis_off()
        self._figures.append((ax, fig))  # rasterised at save, on every worker (see render_figures)
        self.page.y += hh + 0.08
        label = f"Figure (analogue of the paper's Fig. {plot.paper_figure}). " if plot.paper_figure else "Figure. "
        self.paragraph(label + plot.caption, gap=0.22)

    def table(self, df: pd.DataFrame, widths: Mapping[str, int], *, headers: Mapping[str, str] | None = None,
              size: float = TABLE_PT) -> None:
        """A table as monospaced text with wrapped cells, paginated with the header repeated.

        Parameters
        ----------
        df : pandas.DataFrame
            Cells are written with :func:`microimpact.io.formatting.format_cell`.
        widths : mapping of str to int
            The columns to show, in order, and their width in characters.
        headers : mapping of str to str, optional
            Column titles (default: the column names).
        size : float
            Font size [pt]; reduced when the table is wider than the text.
        """
        headers = dict(headers or {})
        cols = [c for c in widths if c in df.columns]
        # a column is at least as wide as its longest word or number, so that wrapping never splits one
        # across lines (a header 'impacts' once read 'impact' / 's'); a wider table is set smaller
        widths = {c: max([widths[c], *(len(w) for w in str(headers.get(c, c)).split()),
                          *(len(w) for v in df[c] for w in format_cell(v).split())]) for c in cols}
        total = sum(widths[c] for c in cols) + 2 * (len(cols) - 1)
        char_w = size * 0.602 / 72  # DejaVu Sans Mono advance width [in]
        size = size if total * char_w <= TEXT_WIDTH else size * TEXT_WIDTH / (total * char_w)

        def fmt_row(cells: list[list[str]]) -> list[str]:
            n = max(len(c) for c in cells)
            return ["  ".join((c[i] if i < len(c) else "").ljust(widths[col]) for c, col in zip(cells, cols)).rstrip()
                    for i in range(n)]

        head = fmt_row([wrap(headers.get(c, c), widths[c]) for c in cols]) + ["-" * total]
        rows = [fmt_row([wrap(format_cell(r[c]), widths[c]) for c in cols]) for _, r in df.iterrows()]
        self._table_blocks(head, rows, size)

    def _table_blocks(self, head: list[str], rows: list[list[str]], size: float) -> None:
        """Write table rows in page-sized blocks, each under the header."""
        line_h = size * 1.3 / 72
        i = 0
        while i < len(rows):
            self.ensure(line_h * (len(head) + len(rows[i])))
            avail = PAGE_SIZE[1] - BOTTOM - self.page.y
            block = list(head)
            while i < len(rows) and (len(block) + len(rows[i])) * line_h <= avail:
                block += rows[i]
                i += 1
            if len(block) == len(head):  # a single row taller than a page: cut it
                block += rows[i][: max(1, int(avail / line_h) - len(block))]
                i += 1
            self._text(MARGIN_X, self.page.y, "\n".join(block), fontsize=size, family="monospace", linespacing=1.3)
            self.page.y += line_h * len(block) + 0.15
            if i < len(rows):
                self.new_page(self._current)
                self._text(MARGIN_X, self.page.y, f"{self._current} (continued)", fontsize=10, fontweight="bold")
                self.page.y += 0.26

    # ------------------------------------------------------------------ title page and output
    def title_page(self, subtitle: str, facts: Mapping[str, str], *, warning: str | None = None,
                   footnote: str = "", verdicts: Sequence[tuple[str, str]] = ()) -> None:
        """Insert the title page (title, subtitle, the verdicts as (text, colour) lines, provenance
        facts, contents) in front of the pages."""
        fig = Figure(figsize=PAGE_SIZE)
        W, H = PAGE_SIZE

        def text(x, y, s, **kw):
            fig.text(x / W, 1 - y / H, s, va="top", **kw)

        text(MARGIN_X, 1.3, "\n".join(textwrap.wrap(self.title, 42)), fontsize=20, fontweight="bold", linespacing=1.25)
        text(MARGIN_X, 2.35, "\n".join(textwrap.wrap(subtitle, 95)), fontsize=9, linespacing=1.35)
        y = 3.25
        if warning:
            text(MARGIN_X, y, warning, fontsize=11, fontweight="bold", color="#b00000")
            y += 0.3
        for line, color in verdicts:
            lines = wrap(line, 95)
            text(MARGIN_X, y, "\n".join(lines), fontsize=9, fontweight="bold", color=color, linespacing=1.3)
            y += 0.17 * len(lines) + 0.06
        y = max(y + 0.1, 3.6)
        text(MARGIN_X, y, "Provenance", fontsize=12, fontweight="bold")
        y += 0.3
        for key, value in facts.items():
            lines = wrap(value, 88)
            text(MARGIN_X, y, key, fontsize=8.5, fontweight="bold")
            text(MARGIN_X + 1.45, y, "\n".join(lines), fontsize=8.5, linespacing=1.3)
            y += 0.17 * len(lines) + 0.06
        y += 0.2
        text(MARGIN_X, y, "Contents", fontsize=12, fontweight="bold")
        y += 0.3
        # a long contents list is set closer, so that it ends above the footnote
        step = min(0.19, (H - FOOTNOTE_Y - 0.15 - y) / max(1, len(self.contents)))
        size = 9 * min(1.0, step / 0.17)
        for name, page in self.contents:
            part = not name[:1].isdigit()
            text(MARGIN_X + (0 if part else 0.2), y, name, fontsize=size, fontweight="bold" if part else "normal")
            text(W - MARGIN_X, y, f"page {page + 2}", fontsize=size, ha="right")
            y += step
        text(MARGIN_X, H - FOOTNOTE_Y, "\n".join(textwrap.wrap(footnote, 110)), fontsize=7.5, color="0.35")
        self.pages.insert(0, Page(fig, "title", 0.0))

    def save(self, path, metadata: Mapping[str, str], *, workers: int = 1) -> None:
        """Write every page to the PDF ``path`` atomically, with running headers and page numbers.

        The figures are rasterised first, by ``workers`` processes (:func:`render_figures`).
        """
        for (ax, _), image in zip(self._figures, render_figures([f for _, f in self._figures], workers)):
            ax.imshow(image, interpolation="none", aspect="auto")
        n = len(self.pages)
        with atomic_path(path) as tmp, _pdf_fonts(self.pages):
            with PdfPages(tmp, metadata=dict(metadata)) as pdf:
                for k, page in enumerate(self.pages, start=1):
                    fig = page.figure
                    if k > 1:  # the title page carries no running header
                        self._header(fig, page.section)
                    fig.text(0.5, 0.4 / PAGE_SIZE[1], f"page {k} of {n}", fontsize=7, color="0.4", ha="center")
                    pdf.savefig(fig)

    def _header(self, fig: Figure, section: str) -> None:
        y = 1.0 - 0.45 / PAGE_SIZE[1]
        fig.text(MARGIN_X / PAGE_SIZE[0], y, self.title, fontsize=7, color="0.4", va="bottom")
        fig.text(1.0 - MARGIN_X / PAGE_SIZE[0], y, section, fontsize=7, color="0.4", va="bottom", ha="right")
        x0, x1 = MARGIN_X / PAGE_SIZE[0], 1 - MARGIN_X / PAGE_SIZE[0]
        y = 1.0 - 0.5 / PAGE_SIZE[1]
        fig.add_artist(Line2D([x0, x1], [y, y], transform=fig.transFigure, color="0.6", lw=0.5))


def _core_fonts_suffice(pages) -> bool:
    """Whether every text of ``pages`` is in the encoding of the PDF core fonts (cp1252)."""
    for page in pages:
        for text in page.figure.findobj(Text):
            try:
                text.get_text().encode("cp1252")
            except UnicodeEncodeError:
                return False
    return True


@contextlib.contextmanager
def _pdf_fonts(pages):
    """Write the text with the PDF core fonts (Helvetica, Courier; not embedded) where they can
    show every character. Embedding DejaVu instead, glyph by glyph, was a large part of the
    report's time (some 100,000 glyphs of tables and captions); text with a character outside cp1252
    (a user's title, a file name) keeps the embedded fonts, so nothing is replaced by "?"."""
    core = _core_fonts_suffice(pages)
    quiet = logging.getLogger("matplotlib.font_manager")
    level = quiet.level
    if core:  # the core fonts' metrics name the weight "medium": matplotlib warns for each text
        quiet.setLevel(logging.ERROR)
    try:
        with matplotlib.rc_context({"pdf.use14corefonts": core}):
            yield
    finally:
        quiet.setLevel(level)


def _render(fig: Figure) -> np.ndarray:
    """The figure as an RGBA image at :data:`DPI`."""
    canvas = FigureCanvasAgg(fig)
    fig.set_dpi(DPI)
    canvas.draw()
    return np.asarray(canvas.buffer_rgba()).copy()


_FORKED: list = []  # (function, items) of fork_map, inherited by the forked workers


def _call_forked(k: int):
    func, items = _FORKED
    return func(items[k])


def fork_map(func, items: list, workers: int = 1) -> list:
    """``[func(x) for x in items]``, by ``workers`` forked processes where that helps.

    The workers inherit ``func`` and ``items`` (matplotlib figures, open datasets): nothing is
    pickled but the index and the result. With one worker, one item, or where ``fork`` is not
    available, the items are processed here in turn; the results are the same.

    Examples
    --------
    >>> fork_map(lambda x: x * x, [1, 2, 3])
    [1, 4, 9]
    """
    if workers <= 1 or len(items) < 2 or "fork" not in multiprocessing.get_all_start_methods():
        return [func(x) for x in items]
    _FORKED[:] = [func, items]
    try:
        with multiprocessing.get_context("fork").Pool(min(workers, len(items))) as pool:
            return pool.map(_call_forked, range(len(items)), chunksize=1)
    finally:
        _FORKED.clear()


def render_figures(figures: list, workers: int = 1) -> list:
    """RGBA images of ``figures``, drawn by ``workers`` processes (:func:`fork_map`).

    Drawing the figures is most of the report's time; they are independent, so
    forked workers draw them side by side.

    Examples
    --------
    A 1 in x 0.5 in figure becomes an image of DPI x DPI/2 pixels, 4 channels.

    >>> from matplotlib.figure import Figure
    >>> (image,) = render_figures([Figure(figsize=(1, 0.5))])
    >>> image.shape == (DPI // 2, DPI, 4)
    True
    """
    return fork_map(_render, figures, workers)
