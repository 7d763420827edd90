"""The report: figures and the PDF, built from result files only (no solver is imported or run here).

- :mod:`.figures`: one function per figure (analogues of the paper's Figs. 3-14, the per-size
  figure of the analyst's material, the benchmark and the Kharaz validation), each returning a
  :class:`~microimpact.report.figures.Plot` (figure and caption).
- :mod:`.pdf`: :func:`~microimpact.report.pdf.build_report`, the PDF from a mapping of result files.
- :mod:`.inputs`: the input keys, the readers of result files and the title-page provenance.
- :mod:`.analyst`, :mod:`.paper`, :mod:`.checks`: the sections of the three parts of the report.
- :mod:`.layout`: A4 page layout on matplotlib (headings, paragraphs, figures, tables).
"""
