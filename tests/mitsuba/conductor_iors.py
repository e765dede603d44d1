"""Prints, as JSON, the RGB complex index (eta, k) that Mitsuba 3's RGB variants give every
conductor it names (`<string name="material" value="Cu"/>`): its spectral tables reduced to
sRGB as Mitsuba reduces them. nprt's table (nprt-scene conductor_ior.rs) was made from this
output, and the agreement test holds the two together.

usage: conductor_iors.py [--rust]   (--rust prints the table's Rust rows instead)
"""
import json
import pathlib
import sys

import mitsuba as mi


def main():
    mi.set_variant("scalar_rgb")
    # Some tables reach slightly outside sRGB; Mitsuba clamps them and says so on stdout.
    mi.set_log_level(mi.LogLevel.Error)
    ior_dir = pathlib.Path(mi.__file__).parent / "data" / "ior"
    names = sorted(p.name[: -len(".eta.spd")] for p in ior_dir.glob("*.eta.spd"))
    table = {}
    for name in names:
        params = mi.traverse(mi.load_dict({"type": "conductor", "material": name}))
        table[name] = [list(map(float, params["eta.value"])), list(map(float, params["k.value"]))]
    if "--rust" in sys.argv:
        for name, (eta, k) in table.items():
            f = lambda v: "[" + ", ".join(f"{x:.6}" for x in v) + "]"
            print(f'    ("{name}", {f(eta)}, {f(k)}),')
    else:
        print(json.dumps(table))


if __name__ == "__main__":
    main()
