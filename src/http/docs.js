"use strict";
function el(tag, cls, content) {
  const e = document.createElement(tag);
  if (cls) { e.className = cls; }
  if (content !== undefined) { e.textContent = content; }
  return e;
}
async function tryGet(path, out) {
  const token = document.getElementById("token").value.trim();
  const response = await fetch(path, { headers: token ? { "Authorization": "Bearer " + token } : {} });
  out.textContent = response.status + " " + response.statusText + "\n\n" + (await response.text()).slice(0, 20000);
}
async function main() {
  const doc = await (await fetch("/v1/openapi.json")).json();
  document.getElementById("title").textContent = doc.info.title + " " + doc.info.version;
  document.getElementById("description").textContent = doc.info.description || "";
  const ops = document.getElementById("ops");
  for (const [path, item] of Object.entries(doc.paths)) {
    for (const [method, op] of Object.entries(item)) {
      const box = el("div", "op");
      box.appendChild(el("span", "method " + method, method));
      box.appendChild(el("span", "path", path));
      box.appendChild(el("span", "", "  " + (op.summary || "")));
      const details = el("details");
      details.appendChild(el("summary", "", "details"));
      details.appendChild(el("p", "", op.description || ""));
      const params = (op.parameters || []).map(p => p.name + " (" + p.in + (p.required ? ", required" : "") + ")");
      if (params.length) { details.appendChild(el("p", "", "Parameters: " + params.join(", "))); }
      const codes = Object.keys(op.responses || {});
      details.appendChild(el("p", "", "Responses: " + codes.join(", ")));
      if (method === "get" && !path.includes("{")) {
        const out = el("pre");
        const button = el("button", "", "Send GET");
        button.addEventListener("click", () => tryGet(path, out));
        details.appendChild(button);
        details.appendChild(out);
      }
      box.appendChild(details);
      ops.appendChild(box);
    }
  }
}
main().catch(e => { document.getElementById("ops").textContent = String(e); });
