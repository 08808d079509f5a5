#!/usr/bin/env python3
"""Derives the corpus's broken universal files from tests/data/uff/symmetric_rotor.unv (an
independent pyuff export, see tests/data/uff/generate.py): each one a single edit a test system or
a hand edit could make. Run from this folder: python3 make_uff.py"""
from pathlib import Path

src = Path("../../../../tests/data/uff/symmetric_rotor.unv").read_text().splitlines(keepends=True)
# Lines 1-21: units and nodes; then one dataset 55 per mode, each from its opening `-1`.
head, m1, m2, m3 = src[:21], src[21:42], src[42:63], src[63:84]

def mode(block, freq=None, zero=False):
    out = list(block)
    if freq is not None:
        out[9] = out[9].replace("3.77460e+01", freq).replace("8.13242e+01", freq)
    if zero:
        for i in range(11, len(out) - 1, 2):
            out[i] = "  0.00000e+00  0.00000e+00  0.00000e+00\n"
    return out

def write(name, lines):
    Path(name).write_text("".join(lines))

# Mode 2 at mode 1's frequency.
write("uff_same_frequency.unv", head + m1 + mode(m2, freq="3.77460e+01") + m3)
# Mode 2's shape zero at every node.
write("uff_zero_shape.unv", head + m1 + mode(m2, zero=True) + m3)
# Mode 1's dataset twice, verbatim.
write("uff_repeated_dataset.unv", head + m1 + m1 + m2 + m3)
# No dataset 55: units and nodes only.
write("uff_no_modes.unv", head)
# Empty file.
write("uff_empty.unv", [])
# Only blank lines.
write("uff_blank.unv", ["\n", "   \n"])
# Mode 3 numbered 999999999999 (record 7 of its dataset 55).
write("uff_huge_mode_number.unv", head + m1 + m2 + m3[:8] + ["         2         4         1 999999999999\n"] + m3[9:])

def scaled(block, factor):
    """The block with every shape value multiplied by `factor` (records 12, 14, … of dataset 55)."""
    out = list(block)
    for i in range(11, len(out) - 1, 2):
        out[i] = "".join(f" {float(v) * factor:.5e}" for v in out[i].split()) + "\n"
    return out

# Mode 2's shape scaled by 1e200 (a test system's own normalisation): the MAC does not care.
write("uff_scaled_1e200.unv", head + m1 + scaled(m2, 1e200) + m3)
# One value of mode 2 (node 101, y) typed as -2.45341e+300: a spike that pairs with nothing.
spike = list(m2)
spike[11] = spike[11].replace("-2.45341e+00", "-2.45341e+300")
write("uff_huge_value.unv", head + m1 + spike + m3)

def in_khz(block):
    """The block with its frequency (record 8) divided by 1000: entered in kHz."""
    out = list(block)
    hz = out[9].split()[0]
    out[9] = out[9].replace(hz, f"{float(hz) / 1000:.5e}", 1)
    return out

# Every frequency in kHz: a unit slip, refused as the CSV path refuses it.
write("uff_in_khz.unv", head + in_khz(m1) + in_khz(m2) + in_khz(m3))
# Mode 2's dataset numbered 1 (record 7), as mode 1's is: which mode did the test mean?
write("uff_mode_number_twice.unv", head + m1 + m2[:8] + ["         2         4         1         1\n"] + m2[9:] + m3)
# Mode 3 numbered -2 (record 7).
write("uff_mode_number_negative.unv", head + m1 + m2 + m3[:8] + ["         2         4         1        -2\n"] + m3[9:])
