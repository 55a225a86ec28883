// The 3D view of a simulated robot, when the server has one (GET /api/scene): viser's own page
// in an iframe. viser serves on its own loopback port; embedding it keeps its 30 Hz websocket
// off our server (docs/decisions/06-the-3d-view-an-iframe-to-viser-not-a-proxy.md says why we did not proxy it).
//
// Looking back is this page's own business. The page makes a random view id, known only to it and
// to viser, and its frame's viser client connects with it (viser's `?websocket=` address, to
// ws://HOST:PORT/view/ID). Looking back, the page asks the server to draw the recorded pose of its
// instant in that view (POST /api/scene/pose {view, pose}): only this page's frame is shown it, over
// the live arm every other page keeps seeing. Closing the page closes the frame, and its pose goes with it.

/** 128 random bits as 32 hex digits: a view id nobody else can guess. */
const randomId = () => Array.from(crypto.getRandomValues(new Uint8Array(16)), (b) => b.toString(16).padStart(2, "0")).join("");

export class SceneView {
  /** @param {function} sendPose the server call that shows a pose in a view: (view, pose) (pose null: the live arm again) */
  constructor(pane, layout, sendPose) {
    this.pane = pane;
    this.layout = layout;
    this.sendPose = sendPose;
    this.view = randomId();
    this.url = null;
    this.wanted = null; // the pose this page's 3D view should show (null: live)
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
    this.sendPose(this.view, wanted && { joints: wanted.joints, bodies: wanted.bodies })
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
    // this page's frame: viser's page, its websocket at this page's own view
    const own = new URL(parsed.href);
    own.searchParams.set("websocket", `${parsed.protocol === "https:" ? "wss:" : "ws:"}//${parsed.host}/view/${this.view}`);
    const frame = document.createElement("iframe");
    frame.src = own.href;
    frame.title = "3D view";
    frame.referrerPolicy = "no-referrer";
    const host = this.pane.querySelector(".scene");
    host.replaceChildren(frame);
    const link = this.pane.querySelector(".scene-link");
    link.href = parsed.href; // a tab of its own: the live arm
    this.pane.hidden = false;
    this.layout.classList.add("with-scene");
    this.showPose(this.wanted); // an instant looked back at before the view was known
  }
}
