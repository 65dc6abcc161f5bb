// What the race view (view.js) and the controller page (drive.js) share; loaded before each.

// The join code (docs/view.md "Pairing"): from the page's own address (?code=…), kept for the
// tab so that a reconnection pairs again; "" when there is none.
function pitwallJoinCode() {
  const fromUrl = new URLSearchParams(location.search).get("code");
  try {
    if (fromUrl) sessionStorage.setItem("pitwall.code", fromUrl);
    return fromUrl || sessionStorage.getItem("pitwall.code") || "";
  } catch { return fromUrl || ""; /* storage off */ }
}
