// KanimLoader: a .kanim clip as three.js objects, the way three.js's own loaders work
// (load(url, onLoad, onProgress, onError), loadAsync(url), parse(buffer)). The result is
// { skeleton, root, clip, kanim }: a Skeleton of Bones named as the BVH's joints (End Sites as
// leaf bones, named as `keyanim sample` names them), the root bone (or a Group holding the roots),
// an AnimationClip of the motion, and the decoded clip (frames, frame time, notes, nodes).
import { AnimationClip, FileLoader, Loader, PropertyBinding } from 'three';
import { decodeKanim } from '../decoder/kanim.js';
import { skeletonSize } from '../decoder/pose.js';
import { buildSkeleton } from './skeleton.js';
import { frameGrid, sampleKeys, buildTracks } from './tracks.js';

// Without a tolerance in its notes, a clip is taken at keyanim encode's default: 0.05% of the
// skeleton's size.
const DEFAULT_TOLERANCE = 0.0005;

// The encoder's tolerance in length units (spec 4.6 notes: tolerance_units=...), or null.
export function clipTolerance(kanim) {
  const v = Number(/^tolerance_units=(.*)$/m.exec(kanim.notes)?.[1]);
  return Number.isFinite(v) && v > 0 ? v : null;
}

// How a track names node i's bone: by name when the name is unique and a track path keeps it
// whole (three.js reserves . : / [ ] in paths), else by the bone's uuid.
function trackNames(bones) {
  const count = new Map();
  for (const b of bones) count.set(b.name, (count.get(b.name) ?? 0) + 1);
  return bones.map((b) => {
    if (b.name === '' || count.get(b.name) > 1) return b.uuid;
    try {
      return PropertyBinding.parseTrackName(`${b.name}.quaternion`).nodeName === b.name ? b.name : b.uuid;
    } catch {
      return b.uuid;
    }
  });
}

export class KanimLoader extends Loader {
  constructor(manager) {
    super(manager);
    this.frameRate = null;  // null: keys at the source frames
    this.tolerance = null;  // null: the clip's own (its notes), else DEFAULT_TOLERANCE x size
  }

  // Keys at `fps` (times k / fps, and the clip's end) instead of the source frames; null: the
  // source frames.
  setFrameRate(fps) {
    if (fps !== null && !(Number.isFinite(fps) && fps > 0)) throw new RangeError(`frame rate ${fps}: not a number > 0`);
    this.frameRate = fps;
    return this;
  }

  // The largest distance, in the clip's length units, allowed between three.js's interpolation
  // of the keys and the curves at any node (keys are added where it would be more); null: half
  // the clip's tolerance; Infinity: no keys added.
  setTolerance(units) {
    if (units !== null && !(units > 0)) throw new RangeError(`tolerance ${units}: not a number > 0`);
    this.tolerance = units;
    return this;
  }

  load(url, onLoad, onProgress, onError) {
    const loader = new FileLoader(this.manager);
    loader.setPath(this.path);
    loader.setResponseType('arraybuffer');
    loader.setRequestHeader(this.requestHeader);
    loader.setWithCredentials(this.withCredentials);
    loader.load(url, (buffer) => {
      try {
        onLoad(this.parse(buffer, clipName(url)));
      } catch (e) {
        e.message = `${url}: ${e.message}`;  // a KanimError keeps its status, where and offset
        if (onError) onError(e); else console.error(e);
        this.manager.itemError(url);
      }
    }, onProgress, onError);
  }

  // buffer: the file's bytes (ArrayBuffer or Uint8Array). Throws the decoder's KanimError
  // (status, where, offset) on a damaged file.
  parse(buffer, name = 'kanim') {
    return this.fromClip(decodeKanim(buffer), name);
  }

  // A clip decoded already: decodeKanim's, or a bank's (decodeBankClip of decoder/bank.js).
  fromClip(kanim, name = 'kanim') {
    const { bones, root, skeleton } = buildSkeleton(kanim.nodes);
    const budget = this.tolerance ?? 0.5 * (clipTolerance(kanim) ?? DEFAULT_TOLERANCE * skeletonSize(kanim.nodes));
    const keys = sampleKeys(kanim, frameGrid(kanim, this.frameRate), budget);
    const duration = Math.max(0, kanim.frameCount - 1) * kanim.frameTime;
    const clip = new AnimationClip(name, duration, buildTracks(kanim, keys, trackNames(bones)));
    clip.userData ??= {};  // three.js before r161 has no AnimationClip.userData
    clip.userData.keyanim = {
      frameCount: kanim.frameCount, frameTime: kanim.frameTime, keyTimes: keys.keys.length,
      interpolationBudget: budget, budgetMet: keys.budgetMet, notes: kanim.notes,
    };
    return { skeleton, root, clip, kanim };
  }
}

// "https://x/walk.kanim?v=2" -> "walk"
function clipName(url) {
  const base = String(url).split(/[?#]/)[0].split('/').pop();
  return decodeURIComponent(base.replace(/\.kanim$/i, '')) || 'kanim';
}
