"""Any bridge, given by its modes: modes files and importers (docs/modal-decks.md).

The deck of an external finite-element model enters cosim as a
:class:`~cosim.core.modal_deck.ModalDeck` (the numerical core's: points,
frequencies, mass-normalised vertical mode shapes, and the contact
interpolation of docs/theory.md §13). This package makes one:

- :func:`read_modes`, :func:`write_modes`: a ``.npz`` file or a folder of CSV files;
- :func:`from_opensees`: the modes of an OpenSeesPy model built in this process (OpenSeesPy is imported
  there, and only there: it is never a dependency of cosim);
- :func:`from_beam`: the beam model's own modes (a beam scenario on the modal route).

An adapter over the core, like :mod:`cosim.sumo` and :mod:`cosim.log` (layer 2 of docs/architecture.md).
"""
from __future__ import annotations

from cosim.core.modal_deck import ModalDeck

from .beam import from_beam
from .files import read_modes, write_modes
from .opensees import from_opensees, generalised_masses

__all__ = ["ModalDeck", "from_beam", "from_opensees", "generalised_masses", "read_modes", "write_modes"]
