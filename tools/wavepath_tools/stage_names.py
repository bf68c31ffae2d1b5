"""The wavefront's stage kernels, in the order of host/render/pipeline.h's kStageNames (the order
the host concatenates their sources in), read from that header so that the tools never keep a
list of their own."""

import os
import re

_REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
_PIPELINE_H = os.path.join(_REPO, "host", "render", "pipeline.h")


def stage_names():
    with open(_PIPELINE_H, encoding="utf-8") as f:
        text = f.read()
    m = re.search(r"kStageNames\s*=\s*\{(.*?)\};", text, re.S)
    if not m:
        raise RuntimeError(f"kStageNames not found in {_PIPELINE_H}")
    names = re.findall(r'"(\w+)"', m.group(1))
    if not names:
        raise RuntimeError(f"kStageNames in {_PIPELINE_H} is empty")
    return names
