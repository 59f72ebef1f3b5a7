#!/usr/bin/env python3
"""Write the spectral metallic paint fixture fixtures/recipes/blue-metallic-spectral.json (an illustration, not a
measured paint), so that its numbers are stated once, with their reasons.

Run by hand:  python3 tools/make_spectral_paints.py   (no dependencies)
"""
import json
import math
import pathlib

grid = list(range(400, 701, 20))
# A blue pigment: weak absorption below ~520 nm, strong above (a logistic edge at 560 nm), flat scattering.
k = [round(0.3 + 2.5 / (1.0 + math.exp(-(w - 560) / 25.0)), 6) for w in grid]
s = [0.5 for _ in grid]
recipe = {
    "model": "paint",
    "name": "Blue metallic, spectral (16 samples, 400–700 nm): aluminium-like flakes in a blue pigmented layer",
    "notes": [
        "An illustration of multi-angle colour (written by tools/make_spectral_paints.py), not a measured paint.",
        "Pigment: K(λ) = 0.3 + 2.5/(1 + exp(−(λ − 560 nm)/25 nm)) per mm (a blue: weak absorption below ~520 nm), "
        "S = 0.5 per mm, concentration 1, layer 0.15 mm over a mid-grey primer (Rg = 0.3).",
        "Flakes: n + ik = 1.0 + 6.5i, wavelength-flat (of the order of aluminium in the visible), spread 12° "
        "(a realistic flake alignment, giving the light-to-dark flop of a metallic), area ratio 0.3, depth 0.075 mm.",
        "Clear coat n = 1.5, smooth.",
    ],
    "form": "physical",
    "wavelengths_nm": grid,
    "clear_coat": {"index": 1.5, "thickness_um": 40},
    "pigmented_layer": {
        "thickness_mm": 0.15,
        "primer_reflectance": [0.3 for _ in grid],
        "pigments": [{"name": "blue", "concentration": 1.0, "k_per_mm": k, "s_per_mm": s}],
    },
    "metallic_flakes": {"n": 1.0, "k": 6.5, "spread_deg": 12.0, "area_ratio": 0.3, "depth_mm": 0.075},
}
path = pathlib.Path(__file__).resolve().parent.parent / "fixtures" / "recipes" / "blue-metallic-spectral.json"
path.write_text(json.dumps(recipe, indent=2, ensure_ascii=False) + "\n")
print("wrote", path)
