// The LanEvil editor's additions to viser's page, run before viser's own code.
// 1. Software WebGL (no GPU: SwiftShader, llvmpipe ...) is told apart by the renderer string. The page then asks
//    viser for a lower pixel ratio (?fixedDpr), and tells the editor in a cookie sent with the websocket
//    handshake, so the tab starts with its 3D view off (the camera preview is the main view).
// 2. Arrow keys on a focused slider move the slider, never the 3D camera (viser's camera keys listen on the
//    document; this listener is added first and stops those keys, and only those, aimed at a form control).
(() => {
  const SOFTWARE = /swiftshader|llvmpipe|softpipe|software|basic render|mesa offscreen/i;
  let renderer = "none";
  try {
    const gl = document.createElement("canvas").getContext("webgl");
    if (gl) {
      const info = gl.getExtension("WEBGL_debug_renderer_info");
      renderer = String(gl.getParameter(info ? info.UNMASKED_RENDERER_WEBGL : gl.RENDERER));
      const lose = gl.getExtension("WEBGL_lose_context");
      if (lose) lose.loseContext();
    }
  } catch (error) {
    renderer = "none";
  }
  const software = renderer === "none" || SOFTWARE.test(renderer);
  const cookie = (name, value) => {
    document.cookie = `${name}=${encodeURIComponent(value)}; path=/; SameSite=Strict`;
  };
  cookie("lanevil_webgl", software ? "software" : "hardware");
  cookie("lanevil_renderer", renderer.slice(0, 160));
  const params = new URLSearchParams(window.location.search);
  if (software && !params.has("fixedDpr")) {
    params.set("fixedDpr", "0.5");
    window.history.replaceState(null, "", `${window.location.pathname}?${params}${window.location.hash}`);
  }
  const FORM = '[role="slider"], input, textarea, select, [contenteditable="true"]';
  const CAMERA_KEYS = /^(Arrow(Up|Down|Left|Right)|Key[WASDQE])$/;  // viser's camera keys; Ctrl+Z still undoes
  document.addEventListener("keydown", (event) => {
    const aimed = event.target instanceof Element && event.target.closest(FORM);
    if (aimed && CAMERA_KEYS.test(event.code) && !event.ctrlKey && !event.metaKey) event.stopImmediatePropagation();
  });
})();
