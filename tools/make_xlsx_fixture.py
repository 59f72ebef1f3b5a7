#!/usr/bin/env python3
"""Write the workbook fixtures of `glossmeter compare` (docs/instrument.md §Workbooks), with openpyxl:

* fixtures/sheets/byk-smart-chart-export.xlsx: a BYK smart-chart style export of one series of five
  tri-angle readings of black-backed glass of n = 1.50, with the makers' statistics columns (Mean, Std, Min,
  Max, Range) on the series' last row, rounded as the export displays them (mean 0.1 GU, std 0.01 GU), and a
  second sheet `Instrument` that is not read by default.
* fixtures/sheets/bad/workbook-wrong-mean.xlsx: the same with `Mean 60°` stated 0.3 GU off the readings.

Provenance: the readings are NOT instrument readings; they are the readings of
fixtures/sheets/byk-semicolon-decimal-comma.csv (constructed around the aperture-averaged predictions for
n = 1.50 glass, 82.05 / 89.14 / 98.97 GU). The statistics are computed here from them (sample standard
deviation, n - 1), independently of glossmeter. The workbook is written with values, not formulas: a file
written by a program that computes nothing holds no cached formula results.

Run by hand from the repository root (pip install openpyxl): python3 tools/make_xlsx_fixture.py
openpyxl writes a fixed timestamp below, so the output is the same bytes on every run of one openpyxl version.
"""
import datetime
import statistics

import openpyxl

READINGS = [  # 20°, 60°, 85° per measurement
    (81.9, 89.1, 99.0),
    (82.2, 89.2, 98.9),
    (82.0, 89.0, 99.1),
    (82.1, 89.2, 98.9),
    (81.9, 89.1, 99.0),
]
ANGLES = ["20°", "60°", "85°"]
SAMPLE = "glass n = 1.50"


def workbook(mean_60_offset=0.0):
    wb = openpyxl.Workbook()
    ws = wb.active
    ws.title = "Measurements"
    ws.append(["# instrument: BYK micro-TRI-gloss (constructed fixture, NOT instrument readings)"])
    head = ["Sample", "Date", *ANGLES]
    for a in ANGLES:
        head += [f"Mean {a}", f"Std {a}"]
    head += ["Min 60°", "Max 60°", "Range 60°"]
    ws.append(head)
    for i, row in enumerate(READINGS):
        cells = [SAMPLE, datetime.datetime(2026, 12, 1, 9, 30 + i), *row]
        if i == len(READINGS) - 1:
            for k in range(3):
                series = [r[k] for r in READINGS]
                mean = round(statistics.mean(series), 1)
                if k == 1:
                    mean = round(mean + mean_60_offset, 1)
                cells += [mean, round(statistics.stdev(series), 2)]
            s60 = [r[1] for r in READINGS]
            cells += [min(s60), max(s60), round(max(s60) - min(s60), 1)]
        ws.append(cells)
    for c in ws[3][1:2]:
        c.number_format = "yyyy-mm-dd hh:mm"
    info = wb.create_sheet("Instrument")
    info.append(["Instrument", "micro-TRI-gloss"])
    info.append(["Serial", "constructed"])
    stamp = datetime.datetime(2026, 12, 1, 12, 0, 0)
    wb.properties.created = stamp
    wb.properties.modified = stamp
    return wb


workbook().save("fixtures/sheets/byk-smart-chart-export.xlsx")
workbook(mean_60_offset=0.3).save("fixtures/sheets/bad/workbook-wrong-mean.xlsx")
print("wrote fixtures/sheets/byk-smart-chart-export.xlsx and fixtures/sheets/bad/workbook-wrong-mean.xlsx")
