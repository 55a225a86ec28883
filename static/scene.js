// The 3D view of a simulated robot, when the server has one (GET /api/scene): viser's own page
// in an iframe. viser serves on its own loopback port; embedding it keeps its 30 Hz websocket
// off our server (docs/architecture.md says why we did not proxy it).

export class SceneView {
  constructor(pane, layout) {
    this.pane = pane;
    this.layout = layout;
    this.url = null;
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
