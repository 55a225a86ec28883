// The server's SVG made inert before it enters the page: parsed as XML (never innerHTML), scripts,
// foreign content, event handlers and external links removed.

const SVG_NS = "http://www.w3.org/2000/svg";
const DROP_ELEMENTS = new Set(["script", "foreignobject", "iframe", "object", "embed", "image", "use", "animate",
  "set", "animatemotion", "animatetransform", "handler", "listener", "style"]);

/** Remove anything active from a parsed SVG: scripts, foreign content, event handlers, external links. */
export function sanitizeSvg(root) {
  const doomed = [];
  for (const el of [root, ...root.querySelectorAll("*")]) {
    if (DROP_ELEMENTS.has(el.localName.toLowerCase())) {
      doomed.push(el);
      continue;
    }
    for (const attr of [...el.attributes]) {
      const name = attr.name.toLowerCase();
      if (name.startsWith("on")
          || ((name === "href" || name.endsWith(":href") || name === "src") && !attr.value.trim().startsWith("#"))
          || (name === "style" && /url\(|javascript:/i.test(attr.value))) {
        el.removeAttribute(attr.name);
      }
    }
  }
  for (const el of doomed) el.remove();
  return root;
}

/** Parse SVG text into a sanitized <svg> element of this document (never innerHTML). */
export function parseSvg(text) {
  const doc = new DOMParser().parseFromString(text, "image/svg+xml");
  const svg = doc.documentElement;
  if (!svg || svg.localName !== "svg" || svg.namespaceURI !== SVG_NS || doc.querySelector("parsererror")) {
    throw new Error("the server's graph is not valid SVG");
  }
  sanitizeSvg(svg);
  return document.adoptNode(svg); // moved, not copied
}
