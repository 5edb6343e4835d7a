// keyanim-three: the .kanim decoder (written from spec/FORMAT.md) and its three.js loader.
export { KanimLoader, clipTolerance } from './three/loader.js';
export { decodeKanim, looksLikeKanim, nodeLabel, KanimError, CHANNEL_TYPES } from './decoder/kanim.js';
export { openBank, decodeBankClip, findBankClip, looksLikeBank } from './decoder/bank.js';
export { samplePose, sampleChannels, channelValue, framePositionAt } from './decoder/sample.js';
export { localRotation, eulerFromQuaternion } from './decoder/rotation.js';
export { worldPositions, skeletonSize } from './decoder/pose.js';
