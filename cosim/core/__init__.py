"""The numerical core: the bridge model, the vehicles and the coupled time step (numpy, scipy, numba).

Nothing here imports SUMO, MCAP, plotting, configuration or study libraries
(``tests/unit/test_architecture.py`` checks it); adapters and orchestration
build on it. The theory it implements is ``docs/theory.md``.

- :mod:`.section`, :mod:`.element`, :mod:`.bridge`: sections, the 7-DOF element, the assembled bridge;
- :mod:`.vehicles`: the vehicle models behind one registry; :mod:`.roughness`: road profiles;
- :mod:`.traffic`: traffic sources and the one "on the deck" rule; :mod:`.sensors`: virtual sensors;
- :mod:`.modal_deck`: a deck given by its modes (any bridge's FE model), with :mod:`.deck_grid` (the contact
  interpolation) and :mod:`.deck_surface` (where the deck is);
- :mod:`.schemes`, :mod:`.bases`, :mod:`.kernels`, :mod:`.coupling`: the coupled step (one compiled loop);
- :mod:`.simulation`: ``simulate`` and its results; :mod:`.quasistatic`: the same traffic without inertia;
- :mod:`.fields`: the per-vehicle fields every output derives from; :mod:`.jit`, :mod:`.banded`: helpers.
"""
