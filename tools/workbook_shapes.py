#!/usr/bin/env python3
"""The worst workbook shapes under the limits of docs/instrument.md §Workbooks, written to a directory, for the
peak-memory measurement of docs/reliability.md §Workbooks (run by hand: `python3 tools/workbook_shapes.py DIR`,
then `/usr/bin/time -v glossmeter compare RECIPE DIR/<shape>` for each). Standard library only."""
import random
import sys
import zipfile

CT = ('<?xml version="1.0" encoding="UTF-8"?><Types xmlns="http://schemas.openxmlformats.org/package/2006/content-types">'
      '<Default Extension="rels" ContentType="application/vnd.openxmlformats-package.relationships+xml"/>'
      '<Default Extension="xml" ContentType="application/xml"/>'
      '<Override PartName="/xl/workbook.xml" ContentType="application/vnd.openxmlformats-officedocument.spreadsheetml.sheet.main+xml"/>'
      '<Override PartName="/xl/worksheets/sheet1.xml" ContentType="application/vnd.openxmlformats-officedocument.spreadsheetml.worksheet+xml"/>'
      '</Types>')
RELS = ('<?xml version="1.0" encoding="UTF-8"?><Relationships xmlns="http://schemas.openxmlformats.org/package/2006/relationships">'
        '<Relationship Id="rId1" Type="http://schemas.openxmlformats.org/officeDocument/2006/relationships/officeDocument" Target="xl/workbook.xml"/></Relationships>')
WB = ('<?xml version="1.0" encoding="UTF-8"?><workbook xmlns="http://schemas.openxmlformats.org/spreadsheetml/2006/main" '
      'xmlns:r="http://schemas.openxmlformats.org/officeDocument/2006/relationships"><sheets>'
      '<sheet name="Readings" sheetId="1" r:id="rId1"/></sheets></workbook>')
WBRELS = ('<?xml version="1.0" encoding="UTF-8"?><Relationships xmlns="http://schemas.openxmlformats.org/package/2006/relationships">'
          '<Relationship Id="rId1" Type="http://schemas.openxmlformats.org/officeDocument/2006/relationships/worksheet" Target="worksheets/sheet1.xml"/>'
          '%s</Relationships>')
SSTREL = '<Relationship Id="rId2" Type="http://schemas.openxmlformats.org/officeDocument/2006/relationships/sharedStrings" Target="sharedStrings.xml"/>'


def col(c):
    s = ""
    c += 1
    while c:
        c, r = divmod(c - 1, 26)
        s = chr(65 + r) + s
    return s


def xlsx(path, rows_xml, sst=None):
    with zipfile.ZipFile(path, "w", zipfile.ZIP_DEFLATED, compresslevel=9) as z:
        z.writestr("[Content_Types].xml", CT)
        z.writestr("_rels/.rels", RELS)
        z.writestr("xl/workbook.xml", WB)
        z.writestr("xl/_rels/workbook.xml.rels", WBRELS % (SSTREL if sst else ""))
        z.writestr("xl/worksheets/sheet1.xml",
                   '<?xml version="1.0" encoding="UTF-8"?><worksheet xmlns="http://schemas.openxmlformats.org/spreadsheetml/2006/main"><sheetData>'
                   + rows_xml + "</sheetData></worksheet>")
        if sst:
            z.writestr("xl/sharedStrings.xml", sst)


def main(out):
    rng = random.Random(1)
    # 1. The most cells the member limit lets through: 100 000 rows × 10 numbers (10⁶ cells), each a different number.
    header = "<row r=\"1\">" + "".join(f'<c r="{col(j)}1" t="inlineStr"><is><t>60° #{j + 1}</t></is></c>' for j in range(10)) + "</row>"
    body = "".join("<row r=\"%d\">%s</row>" % (i, "".join(f'<c r="{col(j)}{i}"><v>{rng.uniform(0, 100):.4f}</v></c>' for j in range(10)))
                   for i in range(2, 100_001))
    xlsx(f"{out}/most-cells.xlsx", header + body)
    # 2. One 50 MB shared string (the biggest text event under the member limit), in a cell.
    s = "".join(rng.choice("ab01") for _ in range(50_000_000))
    sst = ('<?xml version="1.0" encoding="UTF-8"?><sst xmlns="http://schemas.openxmlformats.org/spreadsheetml/2006/main" count="1" uniqueCount="1">'
           f"<si><t>{s}</t></si></sst>")
    xlsx(f"{out}/one-huge-string.xlsx", '<row r="1"><c r="A1" t="s"><v>0</v></c></row>', sst)
    # 3. An .ods of one valued row repeated to just under the cell limit (the 1.1 kB shape of the review).
    for name, repeats in [("ods-repeats-under.ods", 249_999), ("ods-repeats-over.ods", 1_000_000)]:
        content = ('<?xml version="1.0" encoding="UTF-8"?><office:document-content xmlns:office="urn:oasis:names:tc:opendocument:xmlns:office:1.0" '
                   'xmlns:table="urn:oasis:names:tc:opendocument:xmlns:table:1.0" xmlns:text="urn:oasis:names:tc:opendocument:xmlns:text:1.0" office:version="1.2">'
                   '<office:body><office:spreadsheet><table:table table:name="Readings">'
                   '<table:table-row><table:table-cell office:value-type="string"><text:p>sample</text:p></table:table-cell>'
                   + "".join(f'<table:table-cell office:value-type="string"><text:p>{a}°</text:p></table:table-cell>' for a in (20, 60, 85))
                   + "</table:table-row>"
                   f'<table:table-row table:number-rows-repeated="{repeats}"><table:table-cell office:value-type="string"><text:p>p</text:p></table:table-cell>'
                   '<table:table-cell office:value-type="float" office:value="89.1" table:number-columns-repeated="3"/></table:table-row>'
                   "</table:table></office:spreadsheet></office:body></office:document-content>")
        with zipfile.ZipFile(f"{out}/{name}", "w", zipfile.ZIP_DEFLATED) as z:
            z.writestr(zipfile.ZipInfo("mimetype"), "application/vnd.oasis.opendocument.spreadsheet")
            z.writestr("content.xml", content)
            z.writestr("META-INF/manifest.xml", '<?xml version="1.0" encoding="UTF-8"?><manifest:manifest xmlns:manifest="urn:oasis:names:tc:opendocument:xmlns:manifest:1.0" manifest:version="1.2"><manifest:file-entry manifest:full-path="/" manifest:media-type="application/vnd.oasis.opendocument.spreadsheet"/><manifest:file-entry manifest:full-path="content.xml" manifest:media-type="text/xml"/></manifest:manifest>')
    # 4. A text sheet of one-digit readings as large as the input limit allows (16 MiB): the reading limit.
    with open(f"{out}/one-digit-readings.csv", "w") as f:
        f.write("sample," + ",".join(f"60° #{j + 1}" for j in range(20)) + "\n")
        line = "p," + ",".join("1" for _ in range(20)) + "\n"
        f.write(line * ((16 << 20) // len(line) - 8))


if __name__ == "__main__":
    main(sys.argv[1])
