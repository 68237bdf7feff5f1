"""cosim: co-simulation of road traffic and bridge vibration.

The numerical core (``section``, ``element``, ``bridge``) imports only numpy,
scipy and sectionproperties; adapters (SUMO, MCAP) and the command line sit on
top of it.
"""
__version__ = "0.1.0"
