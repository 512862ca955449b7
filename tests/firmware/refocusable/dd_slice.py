#!/usr/bin/env python3
"""An independent Dynamic Depth reader, Python's standard library only.

    dd_slice.py FILE

Reads the JPEG's main XMP packet (APP1 "http://ns.adobe.com/xap/1.0/"), parses it as XML,
follows Container:Directory (the specification's namespaces or GContainer's), slices the items
after the primary from the end of the file by their Item:Length (and Item:Padding), and checks
that each is a valid image of its Item:Mime by its own header (JPEG: SOI and a frame header;
PNG: the signature and IHDR). Prints one line an item:

    <index> <mime> <length> <uri or semantic> <width>x<height>

then `depth <index>` and `original <index>` (the items DepthMap:DepthURI and the Original
Image:ItemURI name), and exits 1 with a message on the first inconsistency.
"""
import struct
import sys
import xml.etree.ElementTree as ET

RDF = "http://www.w3.org/1999/02/22-rdf-syntax-ns#"
DIRECTORIES = [
    ("http://ns.google.com/photos/dd/1.0/container/", "http://ns.google.com/photos/dd/1.0/item/"),
    ("http://ns.google.com/photos/1.0/container/",
     "http://ns.google.com/photos/1.0/container/item/"),
]
DEPTHMAP = "http://ns.google.com/photos/dd/1.0/depthmap/"
IMAGE = "http://ns.google.com/photos/dd/1.0/image/"


def fail(message):
    print("dd_slice: " + message, file=sys.stderr)
    sys.exit(1)


def main_xmp(data):
    if data[:2] != b"\xff\xd8":
        fail("not a JPEG")
    pos = 2
    while pos + 4 <= len(data):
        if data[pos] != 0xFF:
            fail("no marker at %d" % pos)
        marker = data[pos + 1]
        if marker == 0xDA:
            break
        length = struct.unpack(">H", data[pos + 2:pos + 4])[0]
        payload = data[pos + 4:pos + 2 + length]
        signature = b"http://ns.adobe.com/xap/1.0/\x00"
        if marker == 0xE1 and payload.startswith(signature):
            return payload[len(signature):]
        pos += 2 + length
    fail("no main XMP packet")


def attribute_or_child(element, ns, name):
    key = "{%s}%s" % (ns, name)
    if key in element.attrib:
        return element.attrib[key]
    child = element.find(".//" + key)
    return child.text if child is not None else None


def image_size(mime, blob):
    if mime == "image/png":
        if blob[:8] != b"\x89PNG\r\n\x1a\n" or blob[12:16] != b"IHDR":
            return None
        return struct.unpack(">II", blob[16:24])
    if mime == "image/jpeg":
        if blob[:2] != b"\xff\xd8" or blob[-2:] != b"\xff\xd9":
            return None
        pos = 2
        while pos + 9 <= len(blob):
            if blob[pos] != 0xFF:
                return None
            marker = blob[pos + 1]
            length = struct.unpack(">H", blob[pos + 2:pos + 4])[0]
            if 0xC0 <= marker <= 0xCF and marker not in (0xC4, 0xC8, 0xCC):
                height, width = struct.unpack(">HH", blob[pos + 5:pos + 9])
                return width, height
            pos += 2 + length
    return None


def main():
    if len(sys.argv) != 2:
        fail("usage: dd_slice.py FILE")
    data = open(sys.argv[1], "rb").read()
    root = ET.fromstring(main_xmp(data))
    items = None
    for container, item_ns in DIRECTORIES:
        directory = root.find(".//{%s}Directory" % container)
        if directory is None:
            continue
        items = []
        for li in directory.iter("{%s}li" % RDF):
            item = li.find("{%s}Item" % container)
            if item is None:
                fail("a directory entry without Container:Item")
            length = attribute_or_child(item, item_ns, "Length")
            padding = attribute_or_child(item, item_ns, "Padding")
            items.append({
                "mime": attribute_or_child(item, item_ns, "Mime"),
                "length": int(length or 0),
                "padding": int(padding or 0),
                "uri": attribute_or_child(item, item_ns, "DataURI") or
                       attribute_or_child(item, item_ns, "Semantic") or "-",
            })
        break
    if not items:
        fail("no Container:Directory")
    # The items after the primary end the file.
    end = len(data)
    for item in reversed(items[1:]):
        end -= item["length"] + item["padding"]
        item["bytes"] = data[end:end + item["length"]]
    if end < 4 or data[end - items[0]["padding"] - 2:end - items[0]["padding"]] != b"\xff\xd9":
        fail("the lengths do not end the primary image at its EOI")
    items[0]["bytes"] = data[:end - items[0]["padding"]]
    for index, item in enumerate(items):
        size = image_size(item["mime"], item["bytes"])
        if size is None:
            fail("item %d is not a valid %s" % (index, item["mime"]))
        print("%d %s %d %s %dx%d" % (index, item["mime"], len(item["bytes"]), item["uri"], size[0],
                                     size[1]))
    depth_uri = None
    for depthmap in root.iter("{http://ns.google.com/photos/dd/1.0/camera/}DepthMap"):
        depth_uri = attribute_or_child(depthmap, DEPTHMAP, "DepthURI")
        break
    uris = [item["uri"] for item in items]
    if depth_uri not in uris:
        fail("DepthMap:DepthURI %r names no item" % depth_uri)
    print("depth %d" % uris.index(depth_uri))
    for image in root.iter("{http://ns.google.com/photos/dd/1.0/camera/}Image"):
        if attribute_or_child(image, IMAGE, "ItemSemantic") == "Original":
            uri = attribute_or_child(image, IMAGE, "ItemURI")
            if uri not in uris:
                fail("Image:ItemURI %r names no item" % uri)
            print("original %d" % uris.index(uri))


if __name__ == "__main__":
    main()
