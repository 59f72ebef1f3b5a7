#!/usr/bin/env python3
"""Write the legacy and OpenDocument workbook fixtures of `glossmeter compare` (docs/instrument.md §Workbooks):

* fixtures/sheets/byk-smart-chart-export.xls: the readings of byk-smart-chart-export.xlsx's `Measurements` sheet
  (five tri-angle readings of black-backed glass of n = 1.50) as an Excel 97-2003 (BIFF8) workbook, written
  with xlwt, and a second sheet `Instrument` that is not read by default.
* fixtures/sheets/byk-smart-chart-export.ods: the same two sheets as an OpenDocument spreadsheet, its XML
  written here and zipped with the standard library (the `mimetype` member first and stored, as ODF 1.2 §3.3
  requires).

Provenance: the readings are NOT instrument readings; they are those of tools/make_xlsx_fixture.py (constructed
around the aperture-averaged predictions for n = 1.50 glass, 82.05 / 89.14 / 98.97 GU).

Run by hand from the repository root (pip install xlwt): python3 tools/make_xls_ods_fixtures.py
The zip members carry a fixed timestamp, so the output is the same bytes on every run of one xlwt and one Python.
"""
import zipfile

import xlwt

READINGS = [  # 20°, 60°, 85° per measurement, as in tools/make_xlsx_fixture.py
    (81.9, 89.1, 99.0),
    (82.2, 89.2, 98.9),
    (82.0, 89.0, 99.1),
    (82.1, 89.2, 98.9),
    (81.9, 89.1, 99.0),
]
HEADER = ["Sample", "20°", "60°", "85°"]
SAMPLE = "glass n = 1.50"
INSTRUMENT = [["Instrument", "micro-TRI-gloss"], ["Serial", "constructed"]]


def xls(path):
    wb = xlwt.Workbook(encoding="utf-8")
    ws = wb.add_sheet("Measurements")
    for c, h in enumerate(HEADER):
        ws.write(0, c, h)
    for r, row in enumerate(READINGS, start=1):
        ws.write(r, 0, SAMPLE)
        for c, v in enumerate(row, start=1):
            ws.write(r, c, v)
    info = wb.add_sheet("Instrument")
    for r, row in enumerate(INSTRUMENT):
        for c, v in enumerate(row):
            info.write(r, c, v)
    wb.save(path)


def cell(v):
    if isinstance(v, float):
        return f'<table:table-cell office:value-type="float" office:value="{v}"><text:p>{v}</text:p></table:table-cell>'
    return f'<table:table-cell office:value-type="string"><text:p>{v}</text:p></table:table-cell>'


def table(name, rows):
    body = "".join("<table:table-row>" + "".join(cell(v) for v in row) + "</table:table-row>" for row in rows)
    return f'<table:table table:name="{name}">{body}</table:table>'


def ods(path):
    rows = [HEADER] + [[SAMPLE, *r] for r in READINGS]
    content = (
        '<?xml version="1.0" encoding="UTF-8"?><office:document-content '
        'xmlns:office="urn:oasis:names:tc:opendocument:xmlns:office:1.0" '
        'xmlns:table="urn:oasis:names:tc:opendocument:xmlns:table:1.0" '
        'xmlns:text="urn:oasis:names:tc:opendocument:xmlns:text:1.0" office:version="1.2"><office:body>'
        "<office:spreadsheet>" + table("Measurements", rows) + table("Instrument", INSTRUMENT) +
        "</office:spreadsheet></office:body></office:document-content>"
    )
    manifest = (
        '<?xml version="1.0" encoding="UTF-8"?><manifest:manifest '
        'xmlns:manifest="urn:oasis:names:tc:opendocument:xmlns:manifest:1.0" manifest:version="1.2">'
        '<manifest:file-entry manifest:full-path="/" manifest:media-type="application/vnd.oasis.opendocument.spreadsheet"/>'
        '<manifest:file-entry manifest:full-path="content.xml" manifest:media-type="text/xml"/>'
        "</manifest:manifest>"
    )
    stamp = (2026, 12, 1, 12, 0, 0)
    with zipfile.ZipFile(path, "w") as z:
        for name, text, method in [
            ("mimetype", "application/vnd.oasis.opendocument.spreadsheet", zipfile.ZIP_STORED),
            ("META-INF/manifest.xml", manifest, zipfile.ZIP_DEFLATED),
            ("content.xml", content, zipfile.ZIP_DEFLATED),
        ]:
            info = zipfile.ZipInfo(name, date_time=stamp)
            info.compress_type = method
            z.writestr(info, text.encode("utf-8"))


xls("fixtures/sheets/byk-smart-chart-export.xls")
ods("fixtures/sheets/byk-smart-chart-export.ods")
print("wrote fixtures/sheets/byk-smart-chart-export.xls and fixtures/sheets/byk-smart-chart-export.ods")
