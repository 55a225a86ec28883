// The 3D view of a simulated robot, when the server has one (GET /api/scene): viser's own page
// in an iframe. viser serves on its own loopback port; embedding it keeps its 30 Hz websocket
// off our server (docs/decisions/06-the-3d-view-an-iframe-to-viser-not-a-proxy.md says why we did not proxy it). Looking back, the page asks
// the server to draw the recorded pose of the instant (POST /api/scene/pose) instead of the live arm.

export class SceneView {
  /** @param {function} sendPose the server call that shows a pose (null: the live arm again) */
  constructor(pane, layout, sendPose) {
    this.pane = pane;
    this.layout = layout;
    this.sendPose = sendPose;
    this.url = null;
    this.wanted = null; // the pose the 3D view should show (null: live)
    this.sent = null; // the last one sent
    this.sending = false;
  }

  /** Show recorded `pose` ({seq, joints, bodies} of a status; null: live). One request in flight,
   * the newest pose wins, so scrubbing never queues requests up. */
  showPose(pose) {
    this.wanted = pose || null;
    if (!this.url || this.sending || this.wanted === this.sent) return;
    const wanted = this.wanted;
    this.sending = true;
    this.sendPose(wanted && { joints: wanted.joints, bodies: wanted.bodies })
      .catch(() => {}) // no 3D view on this server after all: nothing to draw
      .finally(() => {
        this.sent = wanted;
        this.sending = false;
        if (this.wanted !== wanted) this.showPose(this.wanted);
      });
  }

  show(url) {
    if (!url || url === this.url) return;
    let parsed;
    try {
      parsed = new URL(url);
    } catch (err) {
      return;
    }
    if (parsed.protocol !== "http:" && parsed.protocol !== "https:") return;
    this.url = url;
    const frame = document.createElement("iframe");
    frame.src = parsed.href;
    frame.title = "3D view";
    frame.referrerPolicy = "no-referrer";
    const host = this.pane.querySelector(".scene");
    host.replaceChildren(frame);
    const link = this.pane.querySelector(".scene-link");
    link.href = parsed.href;
    this.pane.hidden = false;
    this.layout.classList.add("with-scene");
  }
}
