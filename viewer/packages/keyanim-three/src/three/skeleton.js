// The clip's hierarchy as three.js bones: one Bone per node, End Sites as leaf bones, in the
// clip's node order (so skeleton.bones[i] is node i, the order of `keyanim sample --json`), at
// the rest pose (each Offset, no rotation), which is the skeleton's bind pose.
import { Bone, Group, Skeleton } from 'three';
import { nodeLabel } from '../decoder/kanim.js';

// Returns { bones, root, skeleton }: root is the root bone, or a Group holding the roots when
// the clip has several.
export function buildSkeleton(nodes) {
  const bones = nodes.map((node, i) => {
    const bone = new Bone();
    bone.name = nodeLabel(nodes, i);
    bone.position.fromArray(node.offset);
    return bone;
  });
  const roots = [];
  nodes.forEach((node, i) => {
    if (node.parent >= 0) bones[node.parent].add(bones[i]);
    else roots.push(bones[i]);
  });
  let root = roots[0];
  if (roots.length !== 1) {
    root = new Group();
    root.name = 'kanim';
    for (const r of roots) root.add(r);
  }
  // Skeleton's bind matrices are the inverses of the bones' world matrices at construction.
  root.updateMatrixWorld(true);
  return { bones, root, skeleton: new Skeleton(bones) };
}
