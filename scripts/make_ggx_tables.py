"""Regenerate restir_engine/core/data/ggx_tables.npz, the GGX tables the Principled BSDF reads
(microfacet_tables.compute_tables: E 32 x 32, E_avg 32, S 32 x 32 x 16; stratified NDF sampling, a few seconds).
Usage: python scripts/make_ggx_tables.py"""
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
from restir_engine.core.materials.microfacet_tables import TABLE_FILE, compute_tables  # noqa: E402

os.makedirs(os.path.dirname(TABLE_FILE), exist_ok=True)
np.savez_compressed(TABLE_FILE, **compute_tables())
print("wrote", TABLE_FILE)
