#!/usr/bin/env python3
"""Check a binding for pairs across side (left with right) or limb class (front with hind).

    binding_check.py BINDING.json SOURCE.json TARGET.json

SOURCE.json and TARGET.json are `skel-info FILE --format json` of the two skeletons. The side
of a joint is skel-info's (names where they say, else the rest pose). The limb class comes from
the names, independently of the engine: a sided joint is front if the nearest word found on it
or its sided ancestors is an arm word (arm, hand, finger, thumb, clavicle, collar, shoulder,
elbow, wrist, wing) and hind if it is a leg word (leg, thigh, calf, foot, toe, horselink, hip,
knee, ankle); centre joints and sided joints without such words are not classed. Prints one
line: the number of pairs, then 'ok' or each crossing pair; exits 0 either way.
"""
import json
import re
import sys

FRONT = ("arm", "hand", "finger", "thumb", "clavicle", "collar", "shoulder", "elbow", "wrist", "wing")
HIND = ("leg", "thigh", "calf", "foot", "toe", "horselink", "hip", "knee", "ankle")


def word_class(name):
    """'front', 'hind' or None from one joint name (first word found from the left)."""
    low = name.lower()
    best = None
    for cls, words in (("front", FRONT), ("hind", HIND)):
        for w in words:
            at = low.find(w)
            if at >= 0 and (best is None or at < best[0]):
                best = (at, cls)
    return best[1] if best else None


def load(path):
    doc = json.load(open(path))
    joints = doc["joints"]
    by_name = {}
    for i, j in enumerate(joints):
        by_name[j["name"]] = i
        # Truebones files carry a '__xyz' suffix that bindings leave out.
        by_name.setdefault(re.sub(r"__[A-Za-z0-9]{3}$", "", j["name"]), i)

    def limb(i):
        k = i
        while k is not None and joints[k]["side"] != "centre":
            cls = word_class(joints[k]["name"])
            if cls:
                return cls
            k = joints[k]["parent"]
        return None

    return joints, by_name, limb


def main():
    binding = json.load(open(sys.argv[1]))
    (sj, sn, slimb), (tj, tn, tlimb) = load(sys.argv[2]), load(sys.argv[3])
    bad = []
    for p in binding["mapping"]:
        s, t = sn.get(p["source"]), tn.get(p["target"])
        if s is None or t is None:
            bad.append(f"{p['source']} -> {p['target']} (name not found)")
            continue
        ss, ts = sj[s]["side"], tj[t]["side"]
        if {ss, ts} == {"left", "right"}:
            bad.append(f"{p['source']} -> {p['target']} (side {ss} -> {ts})")
        sl, tl = slimb(s), tlimb(t)
        if sl and tl and sl != tl:
            bad.append(f"{p['source']} -> {p['target']} (limb {sl} -> {tl})")
    print(f"{len(binding['mapping'])} pairs, " + ("ok: none across side or limb class" if not bad else "ACROSS: " + "; ".join(bad)))


if __name__ == "__main__":
    main()
