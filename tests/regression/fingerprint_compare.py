#!/usr/bin/env python3
"""Compares the summary values of `scripts/fingerprint.sh` with tests/data/fingerprint_reference.txt.

Why a relative tolerance of 1e-8 (measured with BOYCOTT_FINGERPRINT_VISCOSITY_FACTOR, see
scripts/fingerprint.sh): a one-ulp change of the viscosity, which stands for any change in the order
of a sum, moves these values by at most 1e-11 relative (sediment; channel_flow 1e-13, also between
its 1- and 2-rank runs; the others not at all), and a build for another CPU (-march=x86-64 against
-march=native) gives the same bits. A planted 1e-3 change of the viscosity moves every value by
6e-5 relative or more (ergun's f* error, the least). 1e-8 lies 1 000x above the first and 6 000x
below the second.

demo50 is not judged: 0.3 s of settling at 50 deg is chaotic enough that the one-ulp change moves
its <<w_p>> by 1e-3, as much as the planted change does (it is printed; its bits still show a
change in the time-series hash).

Usage: fingerprint_compare.py REFERENCE OUTPUT   (exit 1 with one line per difference)
Regenerate the reference in any commit that changes results on purpose:
  scripts/fingerprint.sh > tests/data/fingerprint_reference.txt
"""
import sys

REL_TOL = 1e-8
CHAOTIC = {"demo50"}


def summaries(path):
    out, hashes = {}, {}
    for line in open(path):
        words = line.split()
        if len(words) >= 2 and words[1] == "failed":
            out[words[0].rstrip(":")] = None
        elif len(words) >= 3 and words[1] == "summary":
            out[words[0]] = {k: float(v) for k, v in (w.split("=", 1) for w in words[2:])}
        elif len(words) == 3:
            hashes[(words[0], words[1])] = words[2]
    return out, hashes


def main():
    ref, ref_hashes = summaries(sys.argv[1])
    new, new_hashes = summaries(sys.argv[2])
    bad = []
    for name, values in ref.items():
        got = new.get(name)
        if got is None:
            bad.append(f"{name}: no summary (the run failed or is missing)")
            continue
        for key, want in values.items():
            have = got.get(key)
            if have is None:
                bad.append(f"{name}: no {key}")
                continue
            rel = abs(have - want) / max(abs(want), abs(have), 1e-300)
            judged = name not in CHAOTIC
            print(f"{name} {key}: {have!r} against {want!r} (relative {rel:.2e}{'' if judged else ', not judged: chaotic'})")
            if judged and rel > REL_TOL:
                bad.append(f"{name} {key} = {have!r} differs from the reference {want!r} by {rel:.2e} > {REL_TOL:g}")
    same = sum(1 for k, h in ref_hashes.items() if new_hashes.get(k) == h)
    print(f"time series and profiles bit for bit as the reference: {same} of {len(ref_hashes)}")
    for line in bad:
        print("FAIL:", line)
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
