"""Reading PoCL's LLVM optimisation remarks (POCL_VECTORIZER_REMARKS=1): which loops the loop
vectoriser vectorised in each stage kernel, and PoCL's work-item loops among them. Shared by
tools/vectorization.py (the table and the ctest) and tools/studies/simd_probe.py. Standard library
only."""

import os
import re
import subprocess

KERNELS = os.path.join(os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))),
                       "kernels")

CODEGEN = re.compile(r"\d+ (stack bytes|instructions) in function$")
# PoCL's workgroup pass inlines the kernel (then _pocl_kernel_NAME) into its launchers.
LAUNCHER = re.compile(r"'_pocl_kernel_(\w+)' inlined into '_pocl_kernel_\1_workgroup")
LOOP_VECTORIZE = re.compile(r"loop not vectorized|vectorized loop|interleaved loop|the cost-model")
VECTORIZED = re.compile(r"vectorized loop \(vectorization width: (\d+), interleaved count: (\d+)\)")
INTERLEAVED = re.compile(r"interleaved loop \(interleaved count: (\d+)\)")


def location_pattern():
    """A remark starts with FILE:LINE:COL (a kernels/ file, as the host's #line directives name
    it) or <unknown>:0:0. PoCL prints remarks with nothing between them, so only known names can
    tell where one ends."""
    names = [os.path.relpath(os.path.join(d, f), KERNELS)
             for d, _, files in os.walk(KERNELS) for f in files]
    names = sorted(names, key=len, reverse=True)
    return re.compile(r"(<unknown>|%s):(\d+):(\d+): " % "|".join(map(re.escape, names)))


def split_remarks(text, pattern):
    """[(location, message)] of PoCL's remark dump."""
    starts = list(pattern.finditer(text))
    return [(f"{m.group(1)}:{m.group(2)}", text[m.end():n.start() if n else len(text)].strip())
            for m, n in zip(starts, starts[1:] + [None])]


def loop_verdicts(remarks):
    """The loop vectoriser's remarks grouped per loop, each {"loop": location, ...}. A loop's
    remarks end with "vectorized loop (...)", "interleaved loop (...)", "loop not vectorized" (its
    reasons, "loop not vectorized: WHY", come before), "... already been vectorized", or, after
    "vectorization is not beneficial", the interleaving verdict that follows it."""
    out, group = [], []
    for where, msg in remarks:
        if not LOOP_VECTORIZE.match(msg):
            continue
        unprofitable = any("vectorization is not beneficial" in m for _, m in group)
        group.append((where, msg))
        if not (unprofitable or VECTORIZED.match(msg) or INTERLEAVED.match(msg)
                or re.fullmatch(r"loop not vectorized( \(.*\))?", msg)
                or "already been vectorized" in msg):
            continue
        verdict = {"loop": where, "vectorized": False}
        if VECTORIZED.match(msg):
            width, count = VECTORIZED.match(msg).groups()
            verdict.update(vectorized=True, width=int(width), interleave=int(count))
        else:
            if INTERLEAVED.match(msg):
                verdict["interleave"] = int(INTERLEAVED.match(msg).group(1))
            verdict["reasons"] = [{"reason": m.split(": ", 1)[-1], "at": w} for w, m in group
                                  if m.startswith("loop not vectorized: ")
                                  or "vectorization is not beneficial" in m]
        out.append(verdict)
        group = []
    return out


def analyse(text):
    """{kernel: {"work_item_loops": [...], "kernel_loops": [...], ...}} for each kernel's first
    compile in PoCL's remark dump (later ones are for the generic work-group size, which PoCL
    builds when asked for the program's binary), in compile order."""
    remarks = split_remarks(text, location_pattern())
    # The code generator's remarks (stack bytes, instructions in function) follow each compile's.
    segments, current = [], []
    for where, msg in remarks:
        if CODEGEN.match(msg):
            if current:
                segments.append(current)
            current = []
        else:
            current.append((where, msg))
    segments.append(current)
    kernels = {}
    for seg in segments:
        marks = [i for i, (_, msg) in enumerate(seg) if LAUNCHER.match(msg)]
        if not marks:
            continue
        name = LAUNCHER.match(seg[marks[0]][1]).group(1)
        if name in kernels:
            continue
        own = {v["loop"] for v in loop_verdicts(seg[:marks[0]])}
        after = loop_verdicts(seg[marks[0]:])
        # The kernel is inlined into two launchers and kept itself: each verdict comes three times.
        wi = []
        for v in after:
            if v["loop"] not in own and v not in wi:
                wi.append(v)
        # LLVM visits a function's innermost loops in program order: when the kernel's own loops
        # come first, the first work-item loop (the kernel's body before any barrier) holds them.
        body_holds_loops = bool(after) and after[0]["loop"] in own
        own = sorted(own, key=lambda at: (at.rpartition(":")[0], int(at.rpartition(":")[2])))
        kernels[name] = {"work_item_loops": wi, "kernel_loops": own,
                         "body_holds_loops": body_holds_loops or (not wi and bool(after))}
    return kernels


def default_device(wavepath):
    """(name, platform) of wavepath's default device, from `wavepath devices`."""
    run = subprocess.run([wavepath, "devices"], capture_output=True, text=True)
    m = re.search(r"^default: (\d+) \((.*)\)$", run.stdout, re.M)
    if run.returncode != 0 or not m:
        return None, None
    row = re.search(r"^%s\s.*$" % m.group(1), run.stdout, re.M)
    return m.group(2), row.group(0) if row else ""


def loop_text(v):
    if v["vectorized"]:
        return f"vectorised ×{v['width']} (interleave {v['interleave']})"
    reasons = {}
    for r in v["reasons"]:
        reasons.setdefault(r["reason"], r["at"])
    text = "; ".join(why if at.startswith("<") else f"{why} ({at})"
                     for why, at in reasons.items()) or "no reason given"
    if "interleave" in v:
        return f"interleaved ×{v['interleave']}, not vectorised: {text}"
    return "not vectorised: " + text


def verdict(k):
    """The Markdown cell for one kernel's analysis, or None when there is no verdict."""
    if k is None or not (k["work_item_loops"] or k["body_holds_loops"]):
        return None
    loops = list(k["work_item_loops"])
    if k["body_holds_loops"]:
        lines = {}  # file: [line, ...]
        for at in k["kernel_loops"]:
            lines.setdefault(at.rpartition(":")[0], []).append(at.rpartition(":")[2])
        parts = ["not vectorised: not innermost (loops at "
                 + "; ".join(f"{f}:{','.join(n)}" for f, n in lines.items()) + ")"]
    else:
        parts = [loop_text(loops.pop(0))]
    parts += ["after a barrier: " + loop_text(v) for v in loops]
    return "<br>".join(parts)
