"""The handlers of the command line's sub-commands, one module per command (private).

:mod:`microimpact.cli` builds the parser from light modules only and imports a command's module
when that command runs (:func:`microimpact.cli._handler`), so ``microimpact --help`` and a usage
error load none of the analysis, the studies or the report. The parser and the handlers share
:mod:`.common`; :mod:`.contacts` turns the contact and input options into a Contact and tables.
"""
