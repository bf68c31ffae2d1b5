#!/usr/bin/env python3
"""Seed corpora for the fuzz targets (standard library only).

    make_seeds.py OUT_DIR [ASSETS_DIR]

Writes OUT_DIR/gltf/, OUT_DIR/environment/ and OUT_DIR/image/. Built-in seeds are always written:
small glTF scenes (JSON with data: URIs and the same as .glb) covering the loader's features, the
repository's own scenes/, small Radiance .hdr (flat and run-length encoded) and OpenEXR files, and
PNGs of every colour type and bit depth for fuzz_image (its JPEG seeds come from
make_compressed_seeds). With ASSETS_DIR (../shared/assets) present, its small .glb files and its
.gltf files whose buffers fit in a data: URI are added, images replaced by a tiny PNG, each
env/*.hdr cropped to its first scanlines (real run-length data, a few KB), and its PNG and JPEG
files under 64 KB as image seeds.
"""

import base64
import json
import os
import struct
import sys
import zlib

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
sys.path.insert(0, os.path.join(ROOT, "scenes"))
import rgbe  # noqa: E402  (scenes/rgbe.py: flat RGBE writing)

MAX_SEED = 64 * 1024  # bytes; larger inputs mostly slow the fuzzer down


def png_rgba(width, height, pixel, empty_idat=False):
    """A width x height RGBA8 PNG of one colour; `empty_idat` puts a zero-length IDAT chunk first
    (valid PNG; stb_image, the decoder before libpng, then copied zero bytes to a null pointer, a
    fuzz finding)."""
    def chunk(kind, data):
        return struct.pack(">I", len(data)) + kind + data + struct.pack(
            ">I", zlib.crc32(kind + data) & 0xFFFFFFFF)
    raw = b"".join(b"\0" + bytes(pixel) * width for _ in range(height))
    return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, 8, 6, 0, 0, 0))
            + (chunk(b"IDAT", b"") if empty_idat else b"")
            + chunk(b"IDAT", zlib.compress(raw)) + chunk(b"IEND", b""))


TINY_PNG = png_rgba(2, 2, (200, 100, 50, 255))


def data_uri(mime, data):
    return "data:%s;base64,%s" % (mime, base64.b64encode(data).decode("ascii"))


def glb(document, binary):
    """A .glb of the JSON document and the BIN chunk (both padded to 4 bytes)."""
    text = json.dumps(document, separators=(",", ":")).encode("utf-8")
    text += b" " * (-len(text) % 4)
    binary += b"\0" * (-len(binary) % 4)
    body = struct.pack("<II", len(text), 0x4E4F534A) + text
    if binary:
        body += struct.pack("<II", len(binary), 0x004E4942) + binary
    return struct.pack("<4sII", b"glTF", 2, 12 + len(body)) + body


def triangle_scene(variant):
    """A one- or two-triangle scene; `variant` switches on features (see builtin_gltf)."""
    pos = struct.pack("<9f", 0, 0, 0, 1, 0, 0, 0, 1, 0)
    nrm = struct.pack("<9f", 0, 0, 1, 0, 0, 1, 0, 0, 1)
    uv = struct.pack("<6f", 0, 0, 1, 0, 0, 1)
    idx = struct.pack("<3H", 0, 1, 2) + b"\0\0"
    buf = pos + nrm + uv + idx
    views = [{"buffer": 0, "byteOffset": 0, "byteLength": 36},
             {"buffer": 0, "byteOffset": 36, "byteLength": 36},
             {"buffer": 0, "byteOffset": 72, "byteLength": 24},
             {"buffer": 0, "byteOffset": 96, "byteLength": 6}]
    accessors = [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3",
                  "min": [0, 0, 0], "max": [1, 1, 0]},
                 {"bufferView": 1, "componentType": 5126, "count": 3, "type": "VEC3"},
                 {"bufferView": 2, "componentType": 5126, "count": 3, "type": "VEC2"},
                 {"bufferView": 3, "componentType": 5123, "count": 3, "type": "SCALAR"}]
    prim = {"attributes": {"POSITION": 0, "NORMAL": 1, "TEXCOORD_0": 2}, "indices": 3,
            "material": 0}
    material = {"pbrMetallicRoughness": {"baseColorFactor": [0.8, 0.5, 0.2, 1.0],
                                         "metallicFactor": 0.0, "roughnessFactor": 0.5}}
    doc = {"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}],
           "nodes": [{"mesh": 0}], "meshes": [{"primitives": [prim]}], "materials": [material],
           "accessors": accessors, "bufferViews": views, "buffers": [{"byteLength": len(buf)}]}
    if variant == "textured":
        doc["images"] = [{"uri": data_uri("image/png", TINY_PNG)}]
        doc["samplers"] = [{"magFilter": 9728, "wrapS": 33071, "wrapT": 33648}]
        doc["textures"] = [{"source": 0, "sampler": 0}]
        doc["extensionsUsed"] = ["KHR_texture_transform"]
        material["pbrMetallicRoughness"]["baseColorTexture"] = {
            "index": 0, "extensions": {"KHR_texture_transform": {
                "offset": [0.5, 0], "rotation": 0.3, "scale": [2, 2]}}}
        material["emissiveTexture"] = {"index": 0}
        material["normalTexture"] = {"index": 0, "scale": 0.5}
    elif variant == "image_in_buffer":
        views.append({"buffer": 0, "byteOffset": len(buf), "byteLength": len(TINY_PNG)})
        buf += TINY_PNG
        doc["images"] = [{"bufferView": 4, "mimeType": "image/png"}]
        doc["textures"] = [{"source": 0}]
        material["pbrMetallicRoughness"]["metallicRoughnessTexture"] = {"index": 0}
    elif variant == "extensions":
        doc["extensionsUsed"] = ["KHR_lights_punctual", "KHR_materials_emissive_strength",
                                 "KHR_materials_ior", "KHR_materials_transmission",
                                 "KHR_materials_volume", "KHR_materials_specular",
                                 "KHR_materials_unlit"]
        doc["extensions"] = {"KHR_lights_punctual": {"lights": [
            {"type": "point", "intensity": 5, "color": [1, 1, 1], "range": 10},
            {"type": "spot", "spot": {"innerConeAngle": 0.1, "outerConeAngle": 0.5}},
            {"type": "directional", "intensity": 2}]}}
        material["emissiveFactor"] = [1, 1, 1]
        material["alphaMode"] = "MASK"
        material["alphaCutoff"] = 0.3
        material["doubleSided"] = True
        material["extensions"] = {
            "KHR_materials_emissive_strength": {"emissiveStrength": 4},
            "KHR_materials_ior": {"ior": 1.33},
            "KHR_materials_transmission": {"transmissionFactor": 0.9},
            "KHR_materials_volume": {"thicknessFactor": 0.1, "attenuationDistance": 2,
                                     "attenuationColor": [0.9, 0.8, 0.7]},
            "KHR_materials_specular": {"specularFactor": 0.5}}
        doc["nodes"] = [{"children": [1, 2, 3, 4], "rotation": [0, 0.7071, 0, 0.7071]},
                        {"mesh": 0, "scale": [-1, 1, 1]},
                        {"extensions": {"KHR_lights_punctual": {"light": 0}},
                         "translation": [0, 2, 0]},
                        {"extensions": {"KHR_lights_punctual": {"light": 1}},
                         "matrix": [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 3, 0, 1]},
                        {"camera": 0, "translation": [0, 0, 5]}]
        doc["cameras"] = [{"type": "perspective",
                           "perspective": {"yfov": 0.7, "znear": 0.1, "aspectRatio": 1.5}}]
    elif variant == "modes":
        # Points, a strip and a fan, no indices, COLOR_0 as normalized bytes; a sparse accessor.
        views.append({"buffer": 0, "byteOffset": len(buf), "byteLength": 12})
        buf += bytes([255, 0, 0, 255, 0, 255, 0, 255, 0, 0, 255, 255])
        views.append({"buffer": 0, "byteOffset": len(buf), "byteLength": 16})
        buf += struct.pack("<H2x3f", 1, 0.5, 0.5, 0.5)
        accessors.append({"bufferView": 4, "componentType": 5121, "normalized": True,
                          "count": 3, "type": "VEC4"})
        accessors.append({"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3",
                          "sparse": {"count": 1,
                                     "indices": {"bufferView": 5, "componentType": 5123},
                                     "values": {"bufferView": 5, "byteOffset": 4}}})
        doc["meshes"] = [{"primitives": [
            {"attributes": {"POSITION": 0, "COLOR_0": 4}, "mode": 0},
            {"attributes": {"POSITION": 5}, "mode": 5},
            {"attributes": {"POSITION": 0, "TEXCOORD_1": 2}, "mode": 6, "material": 0}]}]
    elif variant == "png_idat_too_long":
        # An IDAT chunk claiming more bytes than the file has (stb_image, the decoder before libpng,
        # allocated the claim).
        doc, buf = triangle_scene("plain")
        png = bytearray(png_rgba(2, 2, (9, 8, 7, 255)))
        png[33:37] = struct.pack(">I", 0x6F71D329)
        doc["images"] = [{"uri": data_uri("image/png", bytes(png))}]
        doc["textures"] = [{"source": 0}]
        doc["materials"][0]["pbrMetallicRoughness"]["baseColorTexture"] = {"index": 0}
        return doc, buf
    elif variant == "png_rows_overflow":
        # IHDR stating 4294967295 x 4294967295: the rows' size (7e19 bytes) exceeds any integer;
        # the refusal's message once converted it to one (UBSan, a fuzz finding).
        doc, buf = triangle_scene("plain")
        png = bytearray(png_rgba(2, 2, (9, 8, 7, 255)))
        png[16:24] = struct.pack(">II", 0xFFFFFFFF, 0xFFFFFFFF)
        doc["images"] = [{"uri": data_uri("image/png", bytes(png))}]
        doc["textures"] = [{"source": 0}]
        doc["materials"][0]["pbrMetallicRoughness"]["baseColorTexture"] = {"index": 0}
        return doc, buf
    elif variant == "png_empty_idat":
        doc, buf = triangle_scene("plain")
        doc["images"] = [{"uri": data_uri("image/png", png_rgba(2, 2, (9, 8, 7, 255), True))}]
        doc["textures"] = [{"source": 0}]
        doc["materials"][0]["pbrMetallicRoughness"]["baseColorTexture"] = {"index": 0}
        return doc, buf
    elif variant == "sparse_bad_type":
        # Found by fuzzing (UBSan: a shift by componentType - 5120 < 0): the "modes" scene with
        # sparse indices of componentType 2561. A seed, so every fuzz run replays it.
        doc, buf = triangle_scene("modes")
        doc["accessors"][5]["sparse"]["indices"]["componentType"] = 2561
        return doc, buf
    doc["buffers"][0]["byteLength"] = len(buf)
    return doc, buf


def builtin_gltf(out):
    for variant in ("plain", "textured", "image_in_buffer", "extensions", "modes",
                    "sparse_bad_type", "png_empty_idat", "png_idat_too_long",
                    "png_rows_overflow"):
        doc, buf = triangle_scene(variant)
        with open(os.path.join(out, "builtin_%s.glb" % variant), "wb") as f:
            f.write(glb(doc, buf))
        doc["buffers"][0]["uri"] = data_uri("application/octet-stream", buf)
        with open(os.path.join(out, "builtin_%s.gltf" % variant), "w") as f:
            json.dump(doc, f, separators=(",", ":"))
    for folder in ("scenes", os.path.join("scenes", "failure")):
        for name in sorted(os.listdir(os.path.join(ROOT, folder))):
            path = os.path.join(ROOT, folder, name)
            if name.endswith(".gltf") and os.path.getsize(path) <= MAX_SEED:
                copy(path, os.path.join(out, "repo_" + name))


def copy(src, dst):
    with open(src, "rb") as f, open(dst, "wb") as g:
        g.write(f.read())


def asset_gltf(assets, out):
    """Small .glb as they are; .gltf with external buffers inlined and images made tiny."""
    count = 0
    for folder, _, names in sorted(os.walk(os.path.join(assets, "models"))):
        for name in sorted(names):
            path = os.path.join(folder, name)
            seed = None
            if name.lower().endswith(".glb") and os.path.getsize(path) <= MAX_SEED:
                copy(path, os.path.join(out, "asset_" + name))
                count += 1
            elif name.lower().endswith(".gltf"):
                seed = inline_gltf(path)
            if seed is not None and len(seed) <= MAX_SEED:
                with open(os.path.join(out, "asset_" + name), "wb") as f:
                    f.write(seed)
                count += 1
    return count


def inline_gltf(path):
    with open(path, "rb") as f:
        doc = json.load(f)
    base = os.path.dirname(path)
    for buffer in doc.get("buffers", []):
        uri = buffer.get("uri", "")
        if uri and not uri.startswith("data:"):
            file = os.path.join(base, uri)
            if not os.path.isfile(file) or os.path.getsize(file) > MAX_SEED:
                return None
            with open(file, "rb") as f:
                buffer["uri"] = data_uri("application/octet-stream", f.read())
    for image in doc.get("images", []):
        if "uri" in image:
            image["uri"] = data_uri("image/png", TINY_PNG)
    return json.dumps(doc, separators=(",", ":")).encode("utf-8")


def rle_scanline(pixels):
    """New-style run-length encoding of one scanline of RGBE byte quadruples."""
    w = len(pixels)
    out = bytearray([2, 2, w >> 8, w & 255])
    for c in range(4):
        data = [p[c] for p in pixels]
        x = 0
        while x < w:
            run = 1
            while x + run < w and run < 127 and data[x + run] == data[x]:
                run += 1
            if run >= 3:
                out += bytes([128 + run, data[x]])
                x += run
                continue
            end = x
            while end < w and end - x < 128 and not (
                    end + 2 < w and data[end] == data[end + 1] == data[end + 2]):
                end += 1
            out += bytes([end - x]) + bytes(data[x:end])
            x = end
    return bytes(out)


def builtin_hdr(out):
    gradient = [[(0.1 * x, 0.05 * y, 2.0) for x in range(4)] for y in range(2)]
    rgbe.write_rgbe(os.path.join(out, "builtin_flat.hdr"), 4, 2, gradient)
    width, height = 24, 3
    rows = [[rgbe.encode((1.0 if x < 12 else 0.25 * x, 0.5, 0.01 * y)) for x in range(width)]
            for y in range(height)]
    body = b"".join(rle_scanline(row) for row in rows)
    for name, header in (("rle", b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n"),
                         ("rle_rgbe_exposure", b"#?RGBE\n# comment\nEXPOSURE=1.0\n"
                                               b"FORMAT=32-bit_rle_rgbe\n")):
        with open(os.path.join(out, "builtin_%s.hdr" % name), "wb") as f:
            f.write(header + b"\n" + b"-Y %d +X %d\n" % (height, width) + body)


def crop_hdr(path, rows):
    """The header and the first `rows` scanlines of a .hdr, its resolution line rewritten."""
    with open(path, "rb") as f:
        data = f.read()
    end = data.index(b"\n\n") + 2
    line_end = data.index(b"\n", end)
    parts = data[end:line_end].split()
    if len(parts) != 4 or parts[0] != b"-Y" or parts[2] != b"+X":
        return None
    width, at = int(parts[3]), line_end + 1
    for _ in range(min(rows, int(parts[1]))):
        if data[at] == 2 and data[at + 1] == 2 and data[at + 2] < 128:
            at += 4
            for _ in range(4):
                x = 0
                while x < width:
                    count = data[at]
                    if count > 128:
                        x, at = x + count - 128, at + 2
                    else:
                        x, at = x + count, at + 1 + count
        else:
            at += 4 * width
    return data[:end] + b"-Y %d +X %d\n" % (rows, width) + data[line_end + 1:at]


def exr(width, height, value, origin=(0, 0), pixels=True):
    """An uncompressed scanline OpenEXR file of FLOAT R, G, B, its data window at `origin`; without
    `pixels`, the header and line offset table alone (a file cut short)."""
    def attr(name, kind, payload):
        return name + b"\0" + kind + b"\0" + struct.pack("<i", len(payload)) + payload
    channels = b"".join(c + b"\0" + struct.pack("<iB3xii", 2, 0, 1, 1) for c in (b"B", b"G", b"R"))
    x0, y0 = origin
    box = struct.pack("<4i", x0, y0, x0 + width - 1, y0 + height - 1)
    header = (struct.pack("<I4B", 20000630, 2, 0, 0, 0) + attr(b"channels", b"chlist", channels + b"\0")
              + attr(b"compression", b"compression", b"\0") + attr(b"dataWindow", b"box2i", box)
              + attr(b"displayWindow", b"box2i", box) + attr(b"lineOrder", b"lineOrder", b"\0")
              + attr(b"pixelAspectRatio", b"float", struct.pack("<f", 1))
              + attr(b"screenWindowCenter", b"v2f", struct.pack("<2f", 0, 0))
              + attr(b"screenWindowWidth", b"float", struct.pack("<f", 1)) + b"\0")
    if not pixels:
        return header + struct.pack("<Q", len(header) + 8 * height) * height
    line = b"".join(struct.pack("<%df" % width, *([v] * width)) for v in value[::-1])  # B, G, R
    block_size = 8 + len(line)
    first = len(header) + 8 * height
    table = b"".join(struct.pack("<Q", first + y * block_size) for y in range(height))
    blocks = b"".join(struct.pack("<ii", y0 + y, len(line)) + line for y in range(height))
    return header + table + blocks


def png(width, height, color, depth, rows, palette=None, trns=None, interlace=0):
    """A PNG of colour type `color` and bit depth `depth` from `rows` (each a bytes object of
    packed samples, filter byte not included); interlaced images take the rows of their passes."""
    def chunk(kind, data):
        return struct.pack(">I", len(data)) + kind + data + struct.pack(
            ">I", zlib.crc32(kind + data) & 0xFFFFFFFF)
    body = chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, depth, color, 0, 0, interlace))
    if palette:
        body += chunk(b"PLTE", palette)
    if trns:
        body += chunk(b"tRNS", trns)
    raw = b"".join(b"\0" + r for r in rows)
    return b"\x89PNG\r\n\x1a\n" + body + chunk(b"IDAT", zlib.compress(raw)) + chunk(b"IEND", b"")


def builtin_images(out):
    """fuzz_image's PNGs: every colour type and bit depth the decoder converts, tRNS, Adam7."""
    w, h = 5, 3
    seeds = {
        "grey1": png(w, h, 0, 1, [bytes([0b10110000])] * h),
        "grey2": png(w, h, 0, 2, [bytes([0b00011011, 0b10000000])] * h, trns=b"\0\2"),
        "grey4": png(w, h, 0, 4, [bytes([0x1f, 0xa5, 0x70])] * h),
        "grey16": png(w, h, 0, 16, [bytes(range(2 * w))] * h, trns=b"\x01\x02"),
        "grey_alpha": png(w, h, 4, 8, [bytes(range(2 * w))] * h),
        "rgb": png(w, h, 2, 8, [bytes(range(3 * w))] * h, trns=b"\0\0\0\1\0\2"),
        "rgb16": png(w, h, 2, 16, [bytes(range(6 * w))] * h),
        "rgba16": png(w, h, 6, 16, [bytes(range(8 * w))] * h),
        "palette": png(w, h, 3, 4, [bytes([0x01, 0x23, 0x40])] * h,
                       palette=bytes(range(3 * 5)), trns=b"\x80\x00"),
        # Adam7 of a 3 x 3 RGBA image: passes 1, 4, 5, 6 and 7 have rows of 1, 1, 2, 1 (two
        # rows) and 3 pixels; passes 2 and 3 are empty.
        "adam7": png(3, 3, 6, 8, [bytes(4), bytes(4), bytes(8), bytes(4), bytes(4), bytes(12)],
                     interlace=1),
    }
    # Earlier findings' shape: a header claiming 16000 x 16000 pixels (within the texture limit)
    # over a few bytes of image data (a decoder that trusts IHDR allocates 1 GB before it finds
    # the data missing).
    seeds["claims_16000"] = png(16000, 16000, 6, 8, [bytes(16)] * 4)
    for name, data in seeds.items():
        with open(os.path.join(out, "builtin_%s.png" % name), "wb") as f:
            f.write(data)
    return len(seeds)


def asset_images(assets, out):
    """The shared models' PNG and JPEG files under MAX_SEED bytes."""
    n = 0
    models = os.path.join(assets, "models")
    for root, _, files in os.walk(models):
        for name in sorted(files):
            if os.path.splitext(name)[1].lower() in (".png", ".jpg", ".jpeg"):
                path = os.path.join(root, name)
                if os.path.getsize(path) <= MAX_SEED:
                    with open(path, "rb") as src, open(
                            os.path.join(out, "asset_%d_%s" % (n, name.replace(" ", "_"))),
                            "wb") as dst:
                        dst.write(src.read())
                    n += 1
    return n


def main():
    if len(sys.argv) not in (2, 3):
        sys.exit(__doc__)
    out = sys.argv[1]
    assets = sys.argv[2] if len(sys.argv) == 3 else None
    gltf_dir, env_dir = os.path.join(out, "gltf"), os.path.join(out, "environment")
    image_dir = os.path.join(out, "image")
    for d in (gltf_dir, env_dir, image_dir):
        os.makedirs(d, exist_ok=True)
    builtin_gltf(gltf_dir)
    builtin_images(image_dir)
    builtin_hdr(env_dir)
    with open(os.path.join(env_dir, "builtin.exr"), "wb") as f:
        f.write(exr(3, 2, (0.5, 1.0, 2.0)))
    # Fuzz finding: a data window far from (0, 0), here 2 million pixels wide at y = 10^9 in a cut
    # short file (the loader's slice base pointer overflowed before OpenEXR found the data missing).
    with open(os.path.join(env_dir, "builtin_far_origin.exr"), "wb") as f:
        f.write(exr(2000000, 1, (0.5, 1.0, 2.0), origin=(0, 1000000000), pixels=False))
    # Fuzz finding: an attribute stating 1.6 GB in a small file (OpenEXR allocated it first).
    with open(os.path.join(env_dir, "builtin_long_attribute.exr"), "wb") as f:
        f.write(struct.pack("<I4B", 20000630, 2, 0, 0, 0) + b"junk\0opaqueType\0"
                + struct.pack("<I", 1677721600) + b"x" * 85)
    if assets and os.path.isdir(assets):
        n = asset_gltf(assets, gltf_dir) + asset_images(assets, image_dir)
        env = os.path.join(assets, "env")
        for name in sorted(os.listdir(env)) if os.path.isdir(env) else []:
            if name.endswith(".hdr"):
                seed = crop_hdr(os.path.join(env, name), 2)
                if seed is not None:
                    with open(os.path.join(env_dir, "asset_" + name), "wb") as f:
                        f.write(seed)
                    n += 1
        print("make_seeds: %d seeds from %s" % (n, assets))
    else:
        print("make_seeds: no assets folder; built-in seeds only")


if __name__ == "__main__":
    main()
