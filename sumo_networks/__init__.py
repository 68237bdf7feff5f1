"""SUMO networks, vehicle types and demand levels shipped with cosim (data only).

`bridge.net.xml` is built from `bridge.nod.xml` and `bridge.edg.xml` by
`build_network.py`; `<level>.sumocfg` runs the mix of `vtypes.add.xml` at
the demand of `<level>.rou.xml` (light, medium, heavy, congested).
"""
