"""BVH text of a skeleton with frames of zeros: how the export makes a keyanim.Motion (the
module reads BVH exactly; it has no constructor from arrays), whose channels it then sets."""
from .skeleton import POSITIONS, ROTATIONS


def _number(v):
    return repr(float(v))  # the shortest text that reads back as the same double


def _node(skeleton, j, depth, lines):
    pad = "  " * depth
    if skeleton.end_site[j]:
        # keyanim names an unnamed End Site "End Site of PARENT"; a named one keeps its name.
        unnamed = skeleton.names[j] == "End Site of " + skeleton.names[skeleton.parents[j]]
        lines += [pad + "End Site" + ("" if unnamed else " " + skeleton.names[j]), pad + "{"]
    else:
        lines += [pad + ("ROOT " if skeleton.parents[j] < 0 else "JOINT ") + skeleton.names[j], pad + "{"]
    lines.append(pad + "  OFFSET " + " ".join(_number(v) for v in skeleton.offsets[j]))
    if not skeleton.end_site[j]:
        kinds = skeleton.channels[j]
        lines.append((pad + "  CHANNELS %d %s" % (len(kinds), " ".join(kinds))).rstrip())
    for c in skeleton.children(j):
        _node(skeleton, c, depth + 1, lines)
    lines.append(pad + "}")


def check(skeleton):
    """Raises ValueError for what BVH text cannot hold, naming the node: a name is the rest of
    its line, so it may hold inner spaces but no line break, no space at either end, no brace."""
    for j, name in enumerate(skeleton.names):
        if not name or name != name.strip() or any(ch in "{}\r\n" for ch in name):
            raise ValueError("joint %r: a BVH name cannot be empty, start or end with a space, "
                             "or hold a brace or a line break" % name)
        for kind in skeleton.channels[j]:
            if kind not in ROTATIONS + POSITIONS:
                raise ValueError("joint %r: unknown channel %r" % (name, kind))


def text(skeleton, frame_count, frame_time):
    check(skeleton)
    lines = ["HIERARCHY"]
    for root in [j for j, p in enumerate(skeleton.parents) if p < 0]:
        _node(skeleton, root, 0, lines)
    channels = sum(len(k) for k in skeleton.channels)
    lines += ["MOTION", "Frames: %d" % frame_count, "Frame Time: " + _number(frame_time)]
    row = " ".join(["0"] * channels)
    lines += [row] * frame_count
    return "\n".join(lines) + "\n"
