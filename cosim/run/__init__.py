"""Orchestration: scenarios (configuration lowered to core objects) and what is done with them.

- :mod:`.scenario` (with :mod:`.tables` and :mod:`.config_base`): the scenario file;
- :mod:`.simulate`: a scenario's traffic source and in-memory run; :mod:`.static`: its static load case;
- :mod:`.logged`: a run streamed into an MCAP log (:mod:`.inputs`: the files it embeds);
- :mod:`.replay`, :mod:`.export`, :mod:`.figures`: what is done with a log afterwards;
- :mod:`.outputs`, :mod:`.toml_writer`, :mod:`.payloads`, :mod:`.units`: shared helpers.

Nothing here prints; :mod:`cosim.cli` does.
"""
