"""Regenerate restir_engine/core/data/ggx_albedo.npy, the GGX directional-albedo table the BSDF reads
(bsdf.compute_ggx_albedo_table: 32 x 32 entries, stratified NDF sampling). Usage: python scripts/make_ggx_table.py"""
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
from restir_engine.core.bsdf import TABLE_FILE, compute_ggx_albedo_table  # noqa: E402

os.makedirs(os.path.dirname(TABLE_FILE), exist_ok=True)
np.save(TABLE_FILE, compute_ggx_albedo_table())
print("wrote", TABLE_FILE)
