#!/usr/bin/env python3
"""Write the colour geometries under standards/colour/*.json, with the provenance of every number.

Run by hand:  python3 tools/make_colour_geometries.py   (no dependencies)
Kept as a script so that one citation or assumption is stated once and used by every file that shares it.

Aspecular sign convention (the one of ASTM E2194 / E2539 and the instruments built for them): the aspecular angle
is the viewing angle measured from the specular direction in the plane of illumination, positive towards the
illuminator (i.e. from the specular direction towards the normal). With illumination at 45 deg, aspecular 15 deg
views at 30 deg from the normal on the specular side, 45 deg views along the normal, 110 deg views at 65 deg on
the illuminator's side, and -15 deg views at 60 deg on the specular side.
"""
import json
import pathlib

OUT = pathlib.Path(__file__).resolve().parent.parent / "standards" / "colour"
OUT.mkdir(parents=True, exist_ok=True)

E2194 = "ASTM E2194-14 (Reapproved 2017), Standard Test Method for Multiangle Color Measurement of Metal Flake Pigmented Materials"
E2539 = "ASTM E2539-14 (Reapproved 2017), Standard Test Method for Multiangle Color Measurement of Interference Pigments"
SIGN = ("https://quality-on.blogspot.com/2013/04/instrumental-color-measurement-of.html (BYK-Gardner): 'The aspecular "
        "angle is the viewing angle measured from the specular direction in the illuminator plane. The angle is positive "
        "when measured from the specular direction towards the normal direction'")
ILLUM = {
    "value": 45,
    "source": "ASTM E2194-14 §1.2 and scope: metal flake colour at three aspecular angles under 45° illumination "
              "(https://standards.iteh.ai/catalog/standards/astm/9025f713-acfb-475e-b6b2-ff2942fa4896/astm-e2194-14 ; "
              "E2194-12 excerpt http://m.mydoc123.com/p-530522.html); the 45° illumination itself is from the "
              "standard's title table as commonly cited, the full text was not retrieved",
    "status": "secondary",
}


def stop(value, what):
    return {
        "value": value,
        "source": f"ASSUMED. The angular apertures of E2194 / E2539 instruments (and the angular-selectivity terms of "
                  f"ASTM E2175) were not retrieved. {what}",
        "status": "assumed",
    }


SOURCE = {"shape": "rectangle",
          "in_plane_deg": stop(2.0, "2° full angle, a collimated beam of the order of commercial multi-angle heads"),
          "perpendicular_deg": stop(2.0, "2° full angle, as in plane")}
RECEPTOR = {"shape": "rectangle",
            "in_plane_deg": stop(2.0, "2° full angle, equal to the source so that the source image is not resolved"),
            "perpendicular_deg": stop(2.0, "2° full angle, as in plane")}


def directional(id_, title, standards, aspecular, asp_source, asp_status, notes):
    return {
        "id": id_,
        "title": title,
        "standards": standards,
        "kind": "directional",
        "illumination_deg": ILLUM,
        "aspecular_deg": {"value": aspecular, "source": asp_source, "status": asp_status},
        "source": SOURCE,
        "receptor": RECEPTOR,
        "notes": "Aspecular sign convention: " + SIGN + ". " + notes,
    }


geos = []
for a in (15, 45, 110):
    geos.append(directional(
        f"astm-e2194-{a}", f"ASTM E2194 multi-angle colour: 45° illumination, aspecular {a}°", [E2194], a,
        "ASTM E2194-14 §1.2: metal flake materials need three measurement angles; the three aspecular angles "
        "15°, 45° and 110° are those of the standard as quoted in the issue and by instrument makers (full text not "
        "retrieved; scope at https://standards.iteh.ai/catalog/standards/astm/9025f713-acfb-475e-b6b2-ff2942fa4896/astm-e2194-14)",
        "secondary", "Readings are reflectance factors relative to the perfect reflecting diffuser in the same geometry."))
for a in (25, 75):
    geos.append(directional(
        f"astm-e2194-{a}", f"Extended multi-angle colour: 45° illumination, aspecular {a}° (E2194 extension)", [E2194], a,
        "ASSUMED. The five-angle extension 15°/25°/45°/75°/110° (25° and 75° added, as in DIN 6175-2 and five-angle "
        "instruments) was not confirmed by a retrieved standard text; BYK-Gardner says 'a minimum of three, and "
        "optimally five viewing angles are needed' (https://quality-on.blogspot.com/2013/04/instrumental-color-measurement-of.html) "
        "without listing them",
        "assumed", "Not in the retrieved E2194 text: an assumed extension."))
for a, label in ((-15, "m15"), (15, "15"), (25, "25"), (45, "45"), (75, "75"), (110, "110")):
    geos.append(directional(
        f"astm-e2539-{label}", f"E2539-style multi-angle colour for interference pigments: 45° illumination, aspecular {a}°",
        [E2539], a,
        "ASSUMED (E2539-style). E2539 requires measurement at multiple angles of illumination and detection "
        "(§1.2, https://standards.iteh.ai/catalog/standards/astm/bb791e50-7c39-48cd-8300-b5a1823f4678/astm-e2539-142017); "
        "its table of geometries was not retrieved. This set is the six-angle 45° set of interference-pigment "
        "instruments (-15° on the far side of the specular direction, where interference colours are strongest)",
        "assumed", "Geometries equal to astm-e2194-* share their integrals in the plan."))

D8_VIEW = {
    "value": 8,
    "source": "CIE e-ILV 17-25-095 'eight-degree geometry: irradiation or measurement of reflecting materials at 8° "
              "to the normal … restricted to measurements using an integrating sphere as described in CIE 15' "
              "(https://cie.co.at/eilvterm/17-25-095); CIE 15:2004 geometries di:8° and de:8°",
    "status": "verified",
}
PORT = {
    "value": 5,
    "source": "ASSUMED. The size of the specular port (gloss trap) of de:8° was not retrieved from CIE 15:2004. 5° "
              "half-angle chosen: it excludes the mirror image of a viewing beam whose rays lie within 5° of its axis "
              "(recollection of CIE 15:2004's d:8 tolerances, unverified). The port is a cone around the mirror "
              "direction of the 8° viewing axis",
    "status": "assumed",
}
for mode, port in (("sci", None), ("sce", PORT)):
    g = {
        "id": f"d8-{mode}",
        "title": f"d/8 integrating sphere, specular component {'included' if port is None else 'excluded'} ({mode.upper()})",
        "standards": ["CIE 15:2004 §4 (di:8° / de:8°)", "ASTM E1164", "ISO 7724-1"],
        "kind": "sphere",
        "viewing_deg": D8_VIEW,
        "specular": "included" if port is None else "excluded",
        "notes": "Diffuse illumination (uniform radiance over the hemisphere), viewing along 8°; the viewing beam is "
                 "taken as one direction. Reading = ∫ f(ωi, ω8) cos θi dωi over the illuminated hemisphere (minus the "
                 "specular port for SCE), which by Helmholtz reciprocity is the directional-hemispherical reflectance "
                 "for incidence at 8° (minus what is reflected into the port). Reflectance factor relative to the "
                 "perfect reflecting diffuser under full-hemisphere illumination (the SCI calibration), so a Lambertian "
                 "reads ρ in SCI and ρ(1 − sin²β cos 8°) in SCE (β the port half-angle): the aperture factor.",
    }
    if port is not None:
        g["specular_port_half_angle_deg"] = port
    geos.append(g)

for g in geos:
    (OUT / f"{g['id']}.json").write_text(json.dumps(g, indent=2, ensure_ascii=False) + "\n")
print("wrote", len(geos), "geometries to", OUT)
