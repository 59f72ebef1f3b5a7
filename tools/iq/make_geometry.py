#!/usr/bin/env python3
"""Writes standards/rhopoint-iq-20.json: the Rhopoint IQ-class 20° pixel-array readings (docs/instrument.md §1.9).

Run by hand from the repository root; the pixel windows are derived here from the sourced angles, so that the
file and its derivation agree (python3 tools/iq/make_geometry.py > standards/rhopoint-iq-20.json).
"""
import json

N = 512
W = 14.5 / N  # 0.028320 deg per pixel
IQ_FAQ = "https://www.rhopointinstruments.com/faqs/orange-peel-faqs/how-is-doi-measured/"
IQ_WHY = "https://www.rhopointamericas.com/faqs/why-buy-an-iq-not-a-glossmeter/"
RSPEC = "https://www.rhopointinstruments.com/faqs/what-is-rspec/"
MANUAL = "Novo-Gloss IQ manual p. 7 (https://manualshive.com/en/manual/rhopoint/novo-gloss-iq/1452867?page=10)"
HAZE_E430 = ("Wikipedia 'Haze (optics)' via https://wikimili.com/en/Haze_(optics): ASTM E430 at 20°: narrow-angle haze at "
             "18.1° and 21.9°, i.e. ±1.9° from specular (secondary; the E430 text was not retrieved)")


def centre(k):
    return (k - 0.5 * (N - 1)) * W


def edges(a, b):
    return centre(a) - 0.5 * W, centre(b) + 0.5 * W


def num(value, source, status, plausible=None):
    d = {"value": value, "source": source, "status": status}
    if plausible:
        d["plausible"] = plausible
    return d


def window(name, first, last, why_first, why_last, status, plausible=None):
    lo, hi = edges(first, last)
    span = f" (pixels {first}–{last}: {lo:+.4f}° to {hi:+.4f}° from specular at the pixels' edges)"
    r = {"name": name, "shape": "pixels",
         "pixel_first": num(first, why_first + span, status, plausible and plausible[0]),
         "pixel_last": num(last, why_last + span, status, plausible and plausible[1])}
    return r


# Gloss: the pixels whose centres lie within the ISO 2813 20° receptor's ±0.9°.
g_half = int(round(0.9 / W))  # 32 pixels a side
gloss = (256 - g_half, 255 + g_half)
why_gloss = ("Rhopoint: 'The instrument calculates gloss values using the response from elements of the LDA which "
             f"correspond to the angular tolerances in ISO 2813' ({IQ_FAQ}); the ISO 2813 20° receptor is 1.8° in plane "
             "(DIN EN ISO 13803 abstract, https://dinmedia.de/en/standard/din-en-iso-13803/204173921), so the 64 "
             "pixels nearest the specular direction (32 a side, 1.8125°) are taken; which pixels the maker sums is not "
             "published")
# Rspec: 7 pixels centred on the peak pixel.
peak = 255
rspec = (peak - 3, peak + 3)
why_rspec = ("Rhopoint: 'RSpec is the peak reflectance measured over a very narrow angular band in the specular direction "
             f"(+/-) 0.0991°' ({RSPEC}); ±0.0991° = ±3.5 pixels of 0.02832°, i.e. the peak pixel and 3 on each side "
             "(7 pixels). The array has an even count, so the specular direction falls on the boundary of pixels 255 and "
             "256; the peak pixel is taken as 255 (256 reads the same for an in-plane symmetric profile, to the cos θ "
             "asymmetry). ASSUMED: that the window is centred on the peak pixel and that the peak is at the geometric "
             "specular direction (a tilted or curved specimen moves it)")
# DOI: R0.3, 7-pixel windows centred on the pixel nearest 0.3° from the peak pixel.
d_off = int(round(0.3 / W))  # 11 pixels
why_doi = ("ASSUMED. The IQ reports DOI 'compatible with' ASTM E430 (Rhopoint, https://www.rhopointinstruments.com/?p=148405); "
           "the commonly cited Hunter/Dorigon form DOI = 100·(Rs − R0.3)/Rs with R0.3 read 0.3° off specular (as "
           "standards/astm-e430-30.json; Hunterlab an09_97, https://support.hunterlab.com/hc/en-us/articles/203997375 "
           "confirms 'slightly off specular' only) is taken on the profile: Rs the Rspec window, R0.3 the mean of two "
           f"7-pixel windows (as wide as Rspec's) centred {d_off} pixels ({d_off * W:.4f}°, the whole number of pixels "
           "nearest 0.3°) either side of the peak pixel. The IQ's DOI formula and windows are not published")
# Haze: E430 ±1.9°, 14-pixel windows centred on ±1.9° from the geometric specular direction.
h_half = 7
h_c = 1.9 / W  # 67.09 pixels from the boundary 255|256
h_plus = (int(round(255.5 + h_c - (h_half - 0.5))), int(round(255.5 + h_c + (h_half - 0.5))))
h_minus = (N - 1 - h_plus[1], N - 1 - h_plus[0])
why_haze = (f"{HAZE_E430}. The IQ: 'Gloss Haze values are calculated using the angular tolerances described in ASTM "
            f"E430' ({MANUAL}). ASSUMED: the window width, 14 pixels (0.396°, about the ±0.2° a 'narrow-angle' "
            "receptor spans), centred on ±1.9° from the specular direction; the IQ's haze pixels are not published")

geo = {
    "id": "rhopoint-iq-20",
    "title": "Rhopoint IQ-class goniophotometer at 20°: gloss, haze, log haze, DOI and Rspec from its 512-pixel array",
    "standards": [
        "Rhopoint IQ / IQ-S / Novo-Gloss IQ (maker's methods; Elcometer 408 reports the same readings)",
        "ASTM E430 (haze and DOI, as the maker cites it)",
        "ISO 2813 (20° gloss, as the maker cites it)"
    ],
    "angle_deg": num(20, f"Rhopoint: '512 element LDA @ 20° +/- 7.25°' ({IQ_WHY})", "secondary"),
    "scale": {
        "kind": "black-glass",
        "reference_index": num(1.567, "ASSUMED: the IQ's readings are on the 20° gloss scale (the maker: 'when RSpec is "
                               f"equal to the gloss value the surface is smooth', {RSPEC}), so ISO 2813:2014 §3.3's "
                               "standard n = 1.567 (https://www.52voa.cn/bs-en-iso-2813-2014-pdf-free.html) is taken; "
                               "the maker's calibration tile is not published", "assumed"),
        "assigned_gu": num(100, "ASSUMED, as reference_index: the standard reads 100 GU in every pixel reading, as in "
                           "ISO 2813 §3.3", "assumed")
    },
    "source": {
        "shape": "rectangle",
        "in_plane_deg": num(0.1, "ASSUMED. The IQ's source optics are not published: its source slit is 'perpendicular "
                            f"to the plane of the incident and reflected beams' ({IQ_FAQ}), imaged on the array. The "
                            "maker says a smooth surface reads Rspec equal to its gloss, so the slit's image must fit "
                            "inside the ±0.0991° Rspec window (≤ 0.1982°); and a 0.3° DOI window must see none of a "
                            "mirror's image. 0.1° (3.5 pixels) is taken, inside both; docs/instrument.md §1.9 gives "
                            "how every reading moves over the plausible range", "assumed",
                            {"low": 0.05, "high": 0.1982, "source": "ASSUMED: from about 2 pixels to the whole Rspec "
                             "window (the largest image for which a smooth surface reads Rspec = gloss, as the maker "
                             "says it does)", "status": "assumed"}),
        "perpendicular_deg": num(2.5, "ASSUMED: the shipped D523 / ISO 2813 20° source height (itself assumed, "
                                 "standards-notes §1.2), as the maker says the slit complies with ISO 2813; it fits "
                                 "inside the assumed 3.6° pixel height", "assumed",
                                 {"low": 1.0, "high": 3.0, "source": "ASSUMED: 1° to the 3.0° recollection of the "
                                  "D523 source height", "status": "assumed"})
    },
    "profile": {
        "pixels": num(N, f"Rhopoint: 'a high definition 512 element LDA @ 20° +/- 7.25°' ({IQ_WHY})", "secondary"),
        "pixel_deg": num(round(W, 5), f"Rhopoint: the array 'measures at the 20° ± 7.25° in steps of 0.02832°' ({IQ_FAQ})",
                         "secondary"),
        "perpendicular_deg": num(3.6, "ASSUMED: the pixel height is not published; the ISO 2813 20° receptor height "
                                 "3.6° (secondary, bottmk/visualization docs/metric_bsdf_relation.md §2.2) is taken, "
                                 "so the whole assumed source height is seen", "assumed"),
        "notes": "Pixel k of 512 (0-based) is centred (k − 255.5)·0.02832° from the specular direction in plane; "
                 "the readings below are sums of pixels (receptors of shape 'pixels'), docs/instrument.md §1.9"
    },
    "receptors": [
        window("gloss", gloss[0], gloss[1], why_gloss, why_gloss, "secondary"),
        window("rspec", rspec[0], rspec[1], why_rspec, why_rspec, "assumed"),
        window("doi-minus", peak - d_off - 3, peak - d_off + 3, why_doi, why_doi, "assumed"),
        window("doi-plus", peak + d_off - 3, peak + d_off + 3, why_doi, why_doi, "assumed"),
        window("haze-minus", h_minus[0], h_minus[1], why_haze, why_haze, "assumed"),
        window("haze-plus", h_plus[0], h_plus[1], why_haze, why_haze, "assumed"),
    ],
    "readings": [
        {"quantity": "gloss", "receptor": "gloss"},
        {"quantity": "haze", "receptors": ["haze-minus", "haze-plus"], "specular": "gloss"},
        {"quantity": "log-haze", "receptors": ["haze-minus", "haze-plus"], "specular": "gloss",
         "k": num(1285.1, "ASSUMED for the IQ: its HU_LOG formula is not published; the BYK micro-haze plus log "
                  "scale H_log = K·lg(H/20 + 1), K = 1285.1 (manual pp. 72–73, "
                  "http://www.manualsdir.com/manuals/659523/altana-micro-haze-plus.html?page=72) is taken", "assumed")},
        {"quantity": "doi", "specular": "rspec", "offset": ["doi-minus", "doi-plus"]},
        {"quantity": "gloss", "name": "rspec", "receptor": "rspec"},
    ],
    "notes": ("Every reading is a sum of pixels of the simulated 512-pixel array (docs/instrument.md §1.9): gloss = "
              "100·Φ(gloss pixels)/Φ_standard(gloss pixels); haze = 100·mean Φ(haze windows)/Φ_standard(gloss "
              "pixels) and log haze = K·lg(haze/20 + 1) (the E430 / ISO 13803 form, as astm-e430-20 and iso-13803-20); "
              "DOI = 100·(Φ(Rspec) − mean Φ(R0.3 windows))/Φ(Rspec), all on the specimen; Rspec = 100·Φ(Rspec "
              "window)/Φ_standard(Rspec window). NOT MODELLED, because not public: RIQ (Rhopoint's reflected image "
              "quality: 'a new measurement developed by Rhopoint', http://colorapplications.com/more-than-just-gloss-"
              "theres-also-doi-riq-and-haze-that-can-be-measure/; no formula found), the haze compensation the IQ "
              "applies to bright and metallic paints, and the 'compensation for surface flatness' of its haze (Novo-Gloss "
              "IQ manual p. 7). A sheet's RIQ column is reported as not predicted.")
}
print(json.dumps(geo, indent=2, ensure_ascii=False))
