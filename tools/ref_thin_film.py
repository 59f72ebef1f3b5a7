#!/usr/bin/env python3
"""Reference thin-film and Fresnel values from the `tmm` package (Byrnes, arXiv:1603.02720).

Run by hand (not by CI):  /tmp/venv/bin/python tools/ref_thin_film.py
Writes fixtures/reference/optics-thin-film.json and fixtures/reference/optics-fresnel.json.

tmm conventions match glossmeter's: n + ik with k >= 0, s/p amplitudes of Born & Wolf, transmitted power
Re(n_f cos th_f)/Re(n_i cos th_i)|t|^2 (s) and with conj(cos) (p). tmm clamps the single-pass attenuation of a
coherent layer at Im(delta) <= 35 (T ~ 1e-30), so no case here uses an opaque coherent layer.
Fresnel table: tmm.coh_tmm with a two-medium "stack" [n1, n2] (a single interface), plus mpmath (30 digits)
with Snell's law through the angle (theta_t = asin(sin theta_i / n)) as a second, independent route for the
dielectric rows; the script asserts that both agree to 1e-13.
"""
import json
import datetime
import numpy as np
import mpmath
import tmm

DATE = "2026-11-22"
INF = float("inf")


def provenance(script_note):
    return {
        "script": "tools/ref_thin_film.py",
        "generated": DATE,
        "packages": {"tmm": getattr(tmm, "__version__", "0.2.0"), "numpy": np.__version__, "mpmath": mpmath.__version__},
        "note": script_note,
        "run_at": datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds"),
    }


def cplx(z):
    z = complex(z)
    return [z.real, z.imag]


def run_stack(n_in, layers, n_out, deg, lam):
    """layers: list of (n complex, d nm, coherent bool). Returns dict of rs, rp, ts, tp."""
    n_list = [n_in] + [l[0] for l in layers] + [n_out]
    d_list = [INF] + [l[1] for l in layers] + [INF]
    th = np.radians(deg)
    out = {}
    any_inc = any(not l[2] for l in layers)
    for pol in ("s", "p"):
        if any_inc:
            c_list = ["i"] + ["c" if l[2] else "i" for l in layers] + ["i"]
            res = tmm.inc_tmm(pol, n_list, d_list, c_list, th, lam)
        else:
            res = tmm.coh_tmm(pol, n_list, d_list, th, lam)
        out["r" + pol] = float(res["R"])
        out["t" + pol] = float(res["T"])
    return out


def thin_film_cases():
    cases = []

    def add(name, n_in, layers, n_out, degs, lams):
        for deg in degs:
            for lam in lams:
                res = run_stack(n_in, layers, n_out, deg, lam)
                cases.append({
                    "name": name, "n_in": n_in,
                    "layers": [{"n": cplx(n), "d_nm": d, "coherent": coh} for (n, d, coh) in layers],
                    "n_out": cplx(n_out), "theta_deg": deg, "wavelength_nm": lam, **res,
                })

    degs = [0.0, 15.0, 30.0, 45.0, 60.0, 75.0, 85.0]
    lams = [400.0, 470.0, 550.0, 633.0, 700.0]
    for d_tio2 in (60.0, 100.0, 150.0):
        for k in (0.0, 0.01):
            t = (complex(2.5, k), d_tio2, True)
            mica = (complex(1.58, 0.0), 500.0, False)
            add(f"pearl flake TiO2 {d_tio2:g} nm k={k:g}", 1.5, [t, mica, t], complex(1.5, 0.0), degs, lams)
    add("pearl flake, mica coherent (paper's literal recursion)", 1.5,
        [(complex(2.5, 0.0), 100.0, True), (complex(1.58, 0.0), 500.0, True), (complex(2.5, 0.0), 100.0, True)],
        complex(1.5, 0.0), degs, lams)
    add("AR quarter-wave MgF2 on glass", 1.0, [(complex(1.38, 0.0), 550.0 / 4 / 1.38, True)], complex(1.52, 0.0),
        degs, lams)
    add("3-layer absorbing on metal", 1.0,
        [(complex(2.0, 0.1), 80.0, True), (complex(1.46, 0.0), 120.0, True), (complex(0.05, 2.0), 15.0, True)],
        complex(0.93, 6.33), degs, lams)
    add("incoherent absorbing slab + coating", 1.0,
        [(complex(1.38, 0.0), 100.0, True), (complex(1.5, 1e-6), 2e5, False), (complex(2.1, 0.0), 70.0, True)],
        complex(1.0, 0.0), degs, lams)
    add("frustrated TIR gap", 1.5, [(complex(1.0, 0.0), 200.0, True)], complex(1.5, 0.0), [30.0, 45.0, 60.0], [500.0])
    return cases


def fresnel_mp_dielectric(n, deg):
    with mpmath.workdps(30):
        ti = mpmath.radians(deg)
        st = mpmath.sin(ti) / n
        if st >= 1:
            return 1.0, 1.0
        tt = mpmath.asin(st)
        ci, ct = mpmath.cos(ti), mpmath.cos(tt)
        rs = (ci - n * ct) / (ci + n * ct)
        rp = (n * ci - ct) / (n * ci + ct)
        return float(rs ** 2), float(rp ** 2)


def fresnel_rows():
    rows = []
    for n in (1.5, 1.567, complex(0.93, 6.33)):
        for deg in range(0, 90):
            res = run_stack(1.0, [], complex(n), float(deg), 550.0)
            if not isinstance(n, complex):
                mrs, mrp = fresnel_mp_dielectric(mpmath.mpf(str(n)), deg)
                assert abs(mrs - res["rs"]) < 1e-13 and abs(mrp - res["rp"]) < 1e-13, (n, deg, res, mrs, mrp)
            rows.append({"n": cplx(n), "theta_deg": float(deg), **res})
    return rows


def main():
    tf = {"provenance": provenance("tmm.coh_tmm / tmm.inc_tmm (inc_tmm when any layer is incoherent)"),
          "cases": thin_film_cases()}
    with open("fixtures/reference/optics-thin-film.json", "w") as fh:
        json.dump(tf, fh, indent=1)
        fh.write("\n")
    fr = {"provenance": provenance("single interface from air: tmm.coh_tmm([1, n]); dielectric rows "
                                   "cross-checked against mpmath Born & Wolf via the refraction angle (1e-13)"),
          "rows": fresnel_rows()}
    fr["provenance"]["script"] = "tools/ref_thin_film.py"
    with open("fixtures/reference/optics-fresnel.json", "w") as fh:
        json.dump(fr, fh, indent=1)
        fh.write("\n")
    print(f"wrote {len(tf['cases'])} thin-film cases and {len(fr['rows'])} Fresnel rows")


if __name__ == "__main__":
    main()
