#!/usr/bin/env python3
"""Sanity-check assets/math-font.woff2 (built by tools/font/subset.sh).

Prints the font's names, whether it has a MATH table, the glyph count, the cmap
coverage of a few characters the report uses, that the MATH variants/assemblies of
stretchy and large operators survived subsetting, and the file size.
Exits non-zero if the MATH table or a required character is missing.
Needs fonttools and brotli (pip install fonttools brotli).
"""
import os
import sys

from fontTools.ttLib import TTFont

here = os.path.dirname(os.path.abspath(__file__))
path = sys.argv[1] if len(sys.argv) > 1 else os.path.join(here, "..", "..", "assets", "math-font.woff2")
path = os.path.normpath(path)

font = TTFont(path)
cmap = font.getBestCmap()
glyphs = set(font.getGlyphOrder())
ok = True

print(f"file:    {path}")
print(f"flavor:  {font.flavor}")
print(f"size:    {os.path.getsize(path)} bytes")
print(f"family:  {font['name'].getDebugName(1)!r}  full: {font['name'].getDebugName(4)!r}  "
      f"version: {font['name'].getDebugName(5)!r}")
print(f"tables:  {' '.join(sorted(font.keys()))}")
has_math = "MATH" in font
print(f"MATH table: {'yes' if has_math else 'NO'}")
ok &= has_math
print(f"glyphs:  {len(glyphs)}")
print(f"cmap:    {len(cmap)} code points")

# Characters the report's MathML uses; U+23A1 is only an assembly piece in
# STIX Math 1.1.1 (unencoded), so it is reported but not required.
required = "\U0001D465\U0001D6FF\u03A3\u221A\u22A4\u2212\u2211[]()|\u2016\u0302\u0304\u00AF\u02C6\u02DC\u203E\u20D7\u2032"
optional = "\u23A1"
for ch in required + optional:
    cp = ord(ch)
    present = cp in cmap
    tag = "" if ch in required else " (optional)"
    print(f"  U+{cp:04X} {ch}  {'-> ' + cmap[cp] if present else 'MISSING'}{tag}")
    if ch in required:
        ok &= present

if has_math:
    mv = font["MATH"].table.MathVariants

    def constructions(coverage, records):
        return dict(zip(coverage.glyphs, records)) if coverage else {}

    vert = constructions(mv.VertGlyphCoverage, mv.VertGlyphConstruction)
    horiz = constructions(mv.HorizGlyphCoverage, mv.HorizGlyphConstruction)
    print("MATH variants / assemblies:")
    for ch, table, kind in [("[", vert, "vert"), ("]", vert, "vert"), ("(", vert, "vert"),
                            ("{", vert, "vert"), ("|", vert, "vert"), ("\u221A", vert, "vert"),
                            ("\u2211", vert, "vert"), ("\u222B", vert, "vert"),
                            ("\u0302", horiz, "horiz"), ("\u2192", horiz, "horiz"),
                            ("\u02C6", horiz, "horiz"),
                            ("\u203E", horiz, "horiz")]:
        g = cmap.get(ord(ch))
        c = table.get(g)
        if c is None:
            print(f"  {ch} ({kind}): no construction")
            continue
        variants = [r.VariantGlyph for r in c.MathGlyphVariantRecord]
        parts = [p.glyph for p in c.GlyphAssembly.PartRecords] if c.GlyphAssembly else []
        missing = [x for x in variants + parts if x not in glyphs]
        print(f"  {ch} ({kind}): {len(variants)} size variants, "
              f"{len(parts)} assembly parts{'  MISSING ' + str(missing) if missing else ''}")
        ok &= not missing

print("OK" if ok else "FAILED")
sys.exit(0 if ok else 1)
