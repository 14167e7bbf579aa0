"""ReSTIR: reservoirs, reuse (temporal, spatial) and history shared by every sample type, and the DI sample
type (light points). A second sample type (GI: path vertices) adds its own module beside di.py and reuses
reservoir.py, reuse.py and history.py."""
