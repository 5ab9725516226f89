// WebXR hand tracking read the way the engine takes it: `XRFrame.fillPoses` writes all 25
// joints' poses as 4 × 4 column-major matrices into one array and `fillJointRadii` their radii
// into another, in XRHand's order (the engine's joint order), so a frame is read with nothing
// allocated (`getJointPose` makes an object per joint).

/** Floats per joint pose. */
const MATRIX = 16;
/** Joints of an XRHand. */
const JOINTS = 25;

/** WebXR Hand Input's frame methods (w3.org/TR/webxr-hand-input-1), which @types/webxr leaves out. */
interface HandFrame {
  fillPoses?(spaces: XRSpace[], baseSpace: XRSpace, transforms: Float32Array): boolean;
  fillJointRadii?(jointSpaces: XRJointSpace[], radii: Float32Array): boolean;
}

/** One hand's joints of a frame, read into arrays kept from frame to frame. */
export class XRJoints {
  /** 25 joint poses, 16 floats each (column-major, metres). */
  readonly matrices = new Float32Array(JOINTS * MATRIX);
  /** 25 joint radii (m). */
  readonly radii = new Float32Array(JOINTS);
  /** Each hand's joint spaces in order, listed once (an XRHand's spaces stay the same objects). */
  private readonly spaces = new WeakMap<XRHand, XRJointSpace[]>();

  /** Reads `hand`'s joints in `frame`, posed in `space`; false unless all 25 are tracked. */
  read(xrFrame: XRFrame, hand: XRHand, space: XRSpace): boolean {
    const frame = xrFrame as XRFrame & HandFrame;
    let spaces = this.spaces.get(hand);
    if (!spaces) {
      spaces = Array.from(hand.values());
      this.spaces.set(hand, spaces);
    }
    if (spaces.length !== JOINTS || !frame.fillPoses || !frame.fillJointRadii) return false;
    return frame.fillPoses(spaces, space, this.matrices) && frame.fillJointRadii(spaces, this.radii);
  }
}
