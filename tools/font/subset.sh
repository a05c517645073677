#!/usr/bin/env bash
# Build assets/math-font.woff2: the OpenType MATH font embedded in the HTML report.
#
# Source font: "STIX Math" Regular, Version 1.1.1 (STIXMath-Regular.otf),
#   from the Debian package  fonts-stix  version 1.1.1-4.1  (Debian 12 "bookworm", main),
#   installed at /usr/share/fonts/opentype/stix-word/STIXMath-Regular.otf.
#   Upstream: the STIX Fonts project (STI Pub Companies), SIL Open Font License 1.1.
#   Licence text and copyright lines: assets/math-font-LICENSE.txt.
#
# The STIX licence asks that a Modified Version (a subset is one) carry a different
# name, so the subset is renamed "AccelcalMath" (name IDs 1, 3, 4, 6, 16, 17); the
# copyright (ID 0), trademark (ID 7) and licence (IDs 13, 14) strings are kept as they are.
# Use it from CSS as:  font-family: AccelcalMath, math;
#
# Requirements: python3 with fonttools and brotli (pip install fonttools brotli),
# and the source font. If the font is not installed and this is not run as root,
# the script fetches the .deb with `apt-get download` (no root needed) and unpacks
# it into a temporary directory.
#
# Usage:  tools/font/subset.sh            (from anywhere; writes <repo>/assets/math-font.woff2)
#         SRC_FONT=/path/to/STIXMath-Regular.otf tools/font/subset.sh
# The output is deterministic: running it again on the same inputs gives the same bytes.
set -euo pipefail

DEB_PACKAGE=fonts-stix
DEB_VERSION=1.1.1-4.1
FONT_PATH_IN_DEB=usr/share/fonts/opentype/stix-word/STIXMath-Regular.otf
FAMILY=AccelcalMath

here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
repo="$(cd "$here/../.." && pwd)"
out="$repo/assets/math-font.woff2"

tmp="$(mktemp -d)"
trap 'rm -rf "$tmp"' EXIT

# --- locate the source font ------------------------------------------------
src="${SRC_FONT:-/$FONT_PATH_IN_DEB}"
if [[ ! -f "$src" ]]; then
    echo "subset.sh: $src not found; fetching Debian package $DEB_PACKAGE" >&2
    (cd "$tmp" && apt-get download "$DEB_PACKAGE=$DEB_VERSION" >&2 ||
                  apt-get download "$DEB_PACKAGE" >&2)
    dpkg-deb -x "$tmp"/${DEB_PACKAGE}_*.deb "$tmp/deb"
    src="$tmp/deb/$FONT_PATH_IN_DEB"
fi
if installed="$(dpkg-query -W -f='${Version}' "$DEB_PACKAGE" 2>/dev/null)" &&
   [[ -n "$installed" && "$installed" != "$DEB_VERSION" ]]; then
    echo "subset.sh: warning: $DEB_PACKAGE $installed installed, script written for $DEB_VERSION" >&2
fi

python3 -c 'import fontTools, brotli' 2>/dev/null || {
    echo "subset.sh: needs fonttools and brotli: pip install fonttools brotli" >&2
    exit 1
}

# --- Unicode ranges kept -----------------------------------------------------
unicodes=(
    U+0020-00FF   # Basic Latin + Latin-1 Supplement
    U+02B0-02FF   # Spacing Modifier Letters (ˆ ˇ ˜: stretchy accents in the MATH table)
    U+0300-036F   # Combining Diacritical Marks (hats, bars, tildes, dots over δx)
    U+0370-03FF   # Greek and Coptic
    U+2000-206F   # General Punctuation (spaces, primes, invisible operators)
    U+2070-209F   # Superscripts and Subscripts
    U+20D0-20FF   # Combining Diacritical Marks for Symbols (vector arrow U+20D7)
    U+2100-214F   # Letterlike Symbols
    U+2190-21FF   # Arrows
    U+2200-22FF   # Mathematical Operators
    U+2300-23FF   # Miscellaneous Technical (incl. bracket pieces)
    U+25A0-25FF   # Geometric Shapes
    U+27C0-27EF   # Miscellaneous Mathematical Symbols-A
    U+27F0-27FF   # Supplemental Arrows-A
    U+2980-29FF   # Miscellaneous Mathematical Symbols-B
    U+2A00-2AFF   # Supplemental Mathematical Operators
    # Mathematical Alphanumeric Symbols (U+1D400-1D7FF), only the styles an
    # equation report uses; keeping the whole block would add ~40 KB (fraktur,
    # bold script/fraktur, sans-serif, monospace and sans-serif Greek are dropped).
    U+1D400-1D433 # bold A-z
    U+1D434-1D467 # italic A-z (MathML <mi>x</mi> is drawn as italic 𝑥 U+1D465)
    U+1D468-1D49B # bold italic A-z
    U+1D49C-1D4CF # script A-z (𝒪, 𝒩, ...)
    U+1D538-1D56B # double-struck A-z (𝔼, ...)
    U+1D6A4-1D6A5 # italic dotless i, j
    U+1D6A8-1D6E1 # bold Greek
    U+1D6E2-1D71B # italic Greek (𝛿 U+1D6FF)
    U+1D71C-1D755 # bold italic Greek
    U+1D7CE-1D7D7 # bold digits
    U+1D7D8-1D7E1 # double-struck digits (𝟙)
)
unicode_list="$(IFS=,; echo "${unicodes[*]}")"

# --- subset ------------------------------------------------------------------
# pyftsubset keeps the MATH table and closes over the glyphs it references
# (size variants and assembly parts of stretchy brackets, radicals, big operators,
# italic corrections, accents); --layout-features='*' keeps every GSUB/GPOS feature
# (ssty script-style variants, etc.).
# Hinting is dropped (saves ~14 KB of ~134 KB). Its only visible effect found: at
# text sizes Chromium measures ink slightly smaller without hints, so in borderline
# cases (f(x+h) in a fraction numerator) it keeps the base-size "(" instead of the
# first size variant, which is what TeX would draw. --desubroutinize saves ~3 KB
# after WOFF2 compression.
pyftsubset "$src" \
    --unicodes="$unicode_list" \
    --layout-features='*' \
    --layout-scripts='*' \
    --name-IDs='*' \
    --no-hinting \
    --desubroutinize \
    --notdef-outline \
    --drop-tables+=FFTM \
    --flavor=woff2 \
    --output-file="$tmp/subset.woff2"

# --- rename (the licence requires a different name for a Modified Version) -----
python3 - "$tmp/subset.woff2" "$out" "$FAMILY" <<'PY'
import sys
from fontTools.ttLib import TTFont

src, dst, family = sys.argv[1:4]
font = TTFont(src, recalcTimestamp=False)
name = font["name"]
old = name.getDebugName(5) or ""
new = {
    1: family,
    2: "Regular",
    3: f"{family}-Regular; subset of STIX Math Regular {old.strip()}",
    4: family,
    6: family + "-Regular",
}
# Drop typographic family/subfamily names (not present in the source; be safe).
name.names = [r for r in name.names if r.nameID not in (16, 17)]
for rec in list(name.names):
    if rec.nameID in new:
        name.setName(new[rec.nameID], rec.nameID, rec.platformID, rec.platEncID, rec.langID)
# CFF carries its own font names too.
cff = font["CFF "].cff
cff.fontNames = [family + "-Regular"]
top = cff.topDictIndex[0]
top.FullName = family
top.FamilyName = family
font.flavor = "woff2"
font.save(dst, reorderTables=True)
PY

echo "wrote $out ($(stat -c %s "$out") bytes)"
