"""Random YAML documents for comparing the two readings of ``arrange_up.io.yaml_tree``: block
and flow collections with anchors and aliases of every kind of node, merge keys (of a mapping,
a list of mappings, and wrong ones), explicit tags (standard, local, verbatim, through a
``%TAG`` handle), ``%YAML`` directives, duplicate and equal keys, quoted scalars and tabs
where ruamel also reads them (in flow collections and comments)."""

from __future__ import annotations

import random

SCALARS = [
    "1",
    "-2",
    "017",
    "0x1F",
    "1_000",
    "1.5",
    "1e3",
    ".inf",
    ".nan",
    "true",
    "yes",
    "on",
    "null",
    "~",
    "",
    "2024-01-01",
    "1:30",
    "hello",
    "'q'",
    '"d\\tq"',
    "'1'",
    "=",
    "a b",
]
TAGS = [
    "!!str",
    "!!int",
    "!!float",
    "!!bool",
    "!!null",
    "!thing",
    "!",
    "!<tag:yaml.org,2002:str>",
    "!e!str",
    "!!binary",
    "!!timestamp",
]
CTAGS = ["!!map", "!!seq", "!thing", "!!set", "!!omap", "!e!map", "!"]


class Gen:
    """One document's generator, seeded."""

    def __init__(self, seed):
        self.rng = random.Random(seed)
        self.anchors = []  # (name, kind)
        self.n = 0
        self.tagdir = False

    def scalar(self):
        r = self.rng
        s = r.choice(SCALARS)
        props = []
        if r.random() < 0.15:
            t = r.choice(TAGS)
            if t.startswith("!e!"):
                self.tagdir = True
            if t == "!!binary":
                s = "aGVsbG8="
            if t == "!!timestamp":
                s = "2024-01-02"
            if t in ("!!int",):
                s = r.choice(["1", "0x1f", "017", "'3'"])
            if t == "!!float":
                s = r.choice(["1", "2.5", ".inf"])
            if t == "!!bool":
                s = r.choice(["true", "yes", "False"])
            if t == "!!null":
                s = r.choice(["", "~", "null"])
            props.append(t)
        if r.random() < 0.15:
            name = f"s{self.n}"
            self.n += 1
            props.append("&" + name)
            self.anchors.append((name, "scalar"))
            if r.random() < 0.5:
                props.reverse()
        return " ".join(props + ([s] if s else []))

    def alias(self, kinds=None):
        cands = [a for a in self.anchors if kinds is None or a[1] in kinds]
        if not cands:
            return None
        return "*" + self.rng.choice(cands)[0]

    def node(self, depth, indent, flow=False):
        r = self.rng
        x = r.random()
        if depth > 3 or x < 0.4:
            if r.random() < 0.15:
                a = self.alias()
                if a:
                    return a
            return self.scalar()
        props = []
        if r.random() < 0.1:
            t = r.choice(CTAGS)
            if t.startswith("!e!"):
                self.tagdir = True
            props.append(t)
        anchor = None
        if r.random() < 0.25:
            anchor = f"c{self.n}"
            self.n += 1
            props.append("&" + anchor)
            if r.random() < 0.3:
                props.reverse()
        is_map = r.random() < 0.6
        tagset = "!!set" in props or "!!omap" in props
        if "!!set" in props:
            is_map = True
        if "!!omap" in props:
            is_map = False
        if flow or r.random() < 0.5:
            body = (
                self.flow_map(depth, tagset) if is_map else self.flow_seq(depth, "!!omap" in props)
            )
            out = " ".join(props + [body])
        else:
            body = (
                self.block_map(depth, indent + 2, tagset)
                if is_map
                else self.block_seq(depth, indent + 2, "!!omap" in props)
            )
            out = " ".join(props) + "\n" + body
        if anchor:
            self.anchors.append((anchor, "mapping" if is_map else "sequence"))
        return out

    def key(self):
        r = self.rng
        k = r.choice(["a", "b", "c", "d", "1", "'1'", "x y", "=", "<<", "true", "1.0", "~"])
        if r.random() < 0.05:
            a = self.alias(["scalar"])
            if a:
                return a + " "
        if r.random() < 0.05:
            k = r.choice(["!!str a", "&k" + str(self.n) + " b"])
            self.n += 1
        return k

    def merge_value(self):
        r = self.rng
        x = r.random()
        if x < 0.5:
            a = self.alias(["mapping"])
            if a:
                return a
        if x < 0.7:
            items = [self.alias(["mapping"]) or "{m: 1}" for _ in range(r.randint(1, 3))]
            return "[" + ", ".join(items) + "]"
        if x < 0.8:
            return self.rng.choice(
                ["1", "[1]", "*" + (self.anchors[0][0] if self.anchors else "zz")]
            )
        return "{p: 1, q: 2}"

    def pair(self, depth, flow, indent=0):
        k = self.key()
        if k == "<<" and self.rng.random() < 0.8:
            return f"<<: {self.merge_value()}"
        v = self.node(depth + 1, indent, flow)
        if v.startswith("\n") or "\n" in v.split(" ", 1)[0]:
            return f"{k}:{v}" if v.startswith("\n") else f"{k}: {v}"
        sep = self.rng.choice([": ", ": ", ":\t"]) if flow else ": "
        return f"{k}{sep}{v}"

    def flow_map(self, depth, tagset=False):
        n = self.rng.randint(0, 3)
        if tagset:
            return "{" + ", ".join(self.rng.choice("xyz") for _ in range(n)) + "}"
        return (
            "{"
            + self.rng.choice([", ", ",\t", ", "]).join(self.pair(depth, True) for _ in range(n))
            + "}"
        )

    def flow_seq(self, depth, omap=False):
        n = self.rng.randint(0, 3)
        if omap:
            return "[" + ", ".join(f"{k}: {i}" for i, k in enumerate("pqr"[:n])) + "]"
        return "[" + ", ".join(self.node(depth + 1, 0, True) for _ in range(n)) + "]"

    def block_map(self, depth, indent, tagset=False):
        n = self.rng.randint(1, 4)
        lines = []
        for _ in range(n):
            if tagset:
                lines.append(" " * indent + "? " + self.rng.choice("xyz"))
                continue
            p = self.pair(depth, False, indent)
            lines.append(" " * indent + p)
        return "\n".join(lines)

    def block_seq(self, depth, indent, omap=False):
        n = self.rng.randint(1, 3)
        lines = []
        for i in range(n):
            if omap:
                lines.append(" " * indent + f"- k{i}: {i}")
                continue
            v = self.node(depth + 1, indent, True)
            lines.append(" " * indent + "- " + v)
        return "\n".join(lines)

    def document(self):
        r = self.rng
        body = self.block_map(0, 0)
        head = ""
        if r.random() < 0.2:
            head += "%YAML " + r.choice(["1.1", "1.2"]) + "\n"
        if self.tagdir or r.random() < 0.1:
            head += "%TAG !e! tag:yaml.org,2002:\n"
        if head:
            head += "---\n"
        tail = ""
        if r.random() < 0.03:
            tail = "---\nz: 1\n"
        text = head + body + "\n" + tail
        if r.random() < 0.2:
            text = text.replace("\n", " # c\t\n", 1)
        return text


def documents(count: int, seed: int = 0) -> list[str]:
    """``count`` documents, the same for the same ``seed``."""
    return [Gen(seed * 100_000 + k).document() for k in range(count)]
