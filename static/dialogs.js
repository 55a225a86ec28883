// Modal dialogs (preempt confirmation, set-initial-state editor) and the context menu.
// Texts go in with textContent; the userdata editor validates its JSON before sending.

/** Ask to confirm a preempt; resolves to {reason} or null when cancelled. */
export function confirmPreempt(machine) {
  const dialog = document.getElementById("preempt-dialog");
  dialog.querySelector(".dlg-machine").textContent = machine;
  const reason = dialog.querySelector("input[name=reason]");
  return new Promise((resolve) => {
    dialog.addEventListener("close", () => {
      resolve(dialog.returnValue === "confirm" ? { reason: reason.value.trim() } : null);
    }, { once: true });
    dialog.returnValue = "";
    dialog.showModal();
    dialog.querySelector("#preempt-confirm").focus();
  });
}

/** Parse the editor's text: a JSON object, or an error message. */
function parseUserdata(text) {
  if (!text.trim()) return { value: {} };
  let value;
  try {
    value = JSON.parse(text);
  } catch (err) {
    return { error: "Not valid JSON: " + err.message };
  }
  if (value === null || typeof value !== "object" || Array.isArray(value)) {
    return { error: "Userdata must be a JSON object ({\"key\": value, ...})." };
  }
  return { value };
}

/**
 * The set-initial-state editor.
 * @param {object} opts {container, state, userdata, submit(userdata) -> Promise (rejects with an Error whose message is shown)}
 * @returns {Promise<boolean>} true when the server accepted it
 */
export function editInitialState({ container, state, userdata, submit }) {
  const dialog = document.getElementById("initial-dialog");
  const form = dialog.querySelector("form");
  const area = dialog.querySelector("textarea");
  const error = dialog.querySelector(".dlg-error");
  const send = dialog.querySelector("button[value=send]");
  dialog.querySelector(".dlg-what").textContent = `Start ${container} in state ${state}`;
  area.value = JSON.stringify(userdata || {}, null, 2);
  error.textContent = "";
  const validate = () => {
    const parsed = parseUserdata(area.value);
    error.textContent = parsed.error || "";
    area.classList.toggle("invalid", Boolean(parsed.error));
    send.disabled = Boolean(parsed.error);
    return parsed;
  };
  validate();
  return new Promise((resolve) => {
    const onInput = () => validate();
    const onSubmit = async (e) => {
      const which = e.submitter?.value;
      if (which !== "send") return; // cancel: let the dialog close
      e.preventDefault();
      const parsed = validate();
      if (parsed.error) return;
      send.disabled = true;
      try {
        await submit(parsed.value);
        finish(true);
        dialog.close();
      } catch (err) {
        error.textContent = err.message || String(err);
        send.disabled = false;
      }
    };
    const onClose = () => finish(false);
    let done = false;
    const finish = (ok) => {
      if (done) return;
      done = true;
      area.removeEventListener("input", onInput);
      form.removeEventListener("submit", onSubmit);
      dialog.removeEventListener("close", onClose);
      resolve(ok);
    };
    area.addEventListener("input", onInput);
    form.addEventListener("submit", onSubmit);
    dialog.addEventListener("close", onClose);
    dialog.showModal();
    area.focus();
  });
}

/** A context menu at (x, y) with items [{label, action, disabled, title}]. */
export function showMenu(x, y, title, items) {
  const menu = document.getElementById("menu");
  const head = document.createElement("div");
  head.className = "menu-title";
  head.textContent = title;
  const buttons = items.map((item) => {
    const b = document.createElement("button");
    b.type = "button";
    b.setAttribute("role", "menuitem");
    b.textContent = item.label;
    b.disabled = Boolean(item.disabled);
    if (item.title) b.title = item.title;
    b.addEventListener("click", () => {
      hideMenu();
      item.action();
    });
    return b;
  });
  menu.replaceChildren(head, ...buttons);
  menu.hidden = false;
  const rect = menu.getBoundingClientRect();
  menu.style.left = Math.min(x, innerWidth - rect.width - 4) + "px";
  menu.style.top = Math.min(y, innerHeight - rect.height - 4) + "px";
  setTimeout(() => {
    document.addEventListener("pointerdown", outside, { capture: true });
    document.addEventListener("keydown", escape, { capture: true });
  }, 0);
}

function outside(e) {
  if (!document.getElementById("menu").contains(e.target)) hideMenu();
}

function escape(e) {
  if (e.key === "Escape") hideMenu();
}

function hideMenu() {
  document.getElementById("menu").hidden = true;
  document.removeEventListener("pointerdown", outside, { capture: true });
  document.removeEventListener("keydown", escape, { capture: true });
}
