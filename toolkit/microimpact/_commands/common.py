"""What the command line's parser and its handlers share: the usage error and a few constants."""

from __future__ import annotations

from dataclasses import fields

from microimpact.model.contact import Contact


class UsageError(Exception):
    """A user error: reported in one line, exit status 2."""


#: exit status of ``lammps verify`` when LAMMPS and microimpact disagree (2 is a usage or solver error)
EXIT_DISAGREES = 1
#: --tangential-model of ``lammps fit`` that fits every law its stiffness options allow and ranks them
AUTO_TANGENTIAL = "auto"
#: figure formats of ``microimpact plot --out`` (matplotlib writers)
FIGURE_FORMATS = ("png", "pdf", "svg")
#: the Contact fields, each a command-line option of the commands that build a contact
CONTACT_FIELDS = [f.name for f in fields(Contact)]
