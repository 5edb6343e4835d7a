"""The skeleton as the add-on passes it around: nodes (joints and End Sites, file order) with
their parents, OFFSETs and BVH channels, read from a keyanim.Clip or keyanim.Motion."""
from dataclasses import dataclass, field

import numpy as np

ROTATIONS = ("Xrotation", "Yrotation", "Zrotation")
POSITIONS = ("Xposition", "Yposition", "Zposition")


@dataclass
class Skeleton:
    names: list            # node names as keyanim reports them (End Sites: "End Site of J")
    parents: list          # index of each node's parent, -1 for a root
    offsets: np.ndarray    # (nodes, 3) float64, the OFFSETs in the file's units and axes
    end_site: list         # True for End Sites
    channels: list = field(default_factory=list)  # per node: its channel kinds, in file order

    def children(self, j):
        return [c for c, p in enumerate(self.parents) if p == j]

    def rest_positions(self):
        """Each node's position in the rest pose (OFFSETs summed down the tree)."""
        rest = np.zeros_like(self.offsets)
        for j, p in enumerate(self.parents):
            rest[j] = self.offsets[j] + (rest[p] if p >= 0 else 0.0)
        return rest

    def size(self):
        """Largest side of the rest pose's bounding box, as keyanim measures a skeleton."""
        rest = self.rest_positions()
        return float((rest.max(axis=0) - rest.min(axis=0)).max())


def channels_per_node(names, channel_names):
    """Channel kinds per node from "Joint:Xrotation" names. Channels follow the nodes in file
    order, so each name is matched to the next node so named: joints sharing a name stay apart."""
    per_node = [[] for _ in names]
    node = 0
    for channel in channel_names:
        joint, kind = channel.rsplit(":", 1)
        while names[node] != joint:
            node += 1
        per_node[node].append(kind)
    return per_node


def from_keyanim(source):
    """The Skeleton of a keyanim.Clip or keyanim.Motion (both expose the same properties)."""
    names = list(source.joint_names)
    return Skeleton(names=names, parents=[int(p) for p in source.parents],
                    offsets=np.asarray(source.offsets, dtype=np.float64).reshape(len(names), 3),
                    end_site=[bool(e) for e in source.is_end_site],
                    channels=channels_per_node(names, list(source.channel_names)))
