"""Ready models of published mechanisms, one subpackage per paper; no subpackage imports another.

- ``spherical_leg``   paper 1, the 2RUHU-RUPR-RUR spherical parallel leg
- ``omnileg``         paper 2, the OmniLeg serial-parallel leg
- ``continuum``       paper 3, the cable-driven continuum robot
- ``skid_steer``      paper 4, the skid-steer wheel-track exploration robot
- ``vectored_thrust`` paper 5, the RRR-RR vectored-thrust spherical mechanism
"""
