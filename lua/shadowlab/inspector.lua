-- inspector.lua -- the report's pixel inspector: per configuration, its
-- pixels' estimate, reference, standard error and region in a small script
-- file (images/KEY/inspect.js, loaded by a <script> tag so it opens from
-- disk: browsers refuse file:// fetches), and the page's script that shows
-- a configuration's reference, estimate and signed error at single-pixel
-- zoom and reads the values under the cursor.
--
-- Format (one configuration): SL_INSPECT[KEY] = {w, h, data}, data base64
-- of w x h records of 7 bytes, little-endian: estimate, reference and
-- standard error as u16 (value x 65535, clamped to [0, 1]: 1.5e-5 steps;
-- RGB: the mean of the channels), then the region (metrics.h: 0 not scored,
-- 1 penumbra, 2 umbra, 3 lit, 4 terminator) plus 128 when the estimate is
-- not finite. 7 bytes x 4/3 per pixel: 0.7 MB at 320x240; images over
-- inspector.max_pixels get none.
local sl = package.loaded.shadowlab or require "shadowlab"

local inspector = { max_pixels = 1024 * 768 }

local b64 = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/"

local function base64(s)
  local out, n = {}, #s
  for i = 1, n, 3 do
    local a, b, c = s:byte(i, i + 2)
    local v = a * 65536 + (b or 0) * 256 + (c or 0)
    local q = {}
    for k = 1, 4 do
      local idx = (v >> (6 * (4 - k))) & 63
      q[k] = b64:sub(idx + 1, idx + 1)
    end
    if not b then q[3], q[4] = "=", "=" elseif not c then q[4] = "=" end
    out[#out + 1] = table.concat(q)
  end
  return table.concat(out)
end

local function u16(v)
  if v ~= v then return 0 end
  return math.floor(math.max(0, math.min(1, v)) * 65535 + 0.5)
end

-- The channels' mean at pixel (x, y) (1-based) of an Image.
local function mean_at(img, x, y, channels)
  local s = 0
  for c = 1, channels do s = s + img:get(x, y, c) end
  return s / channels
end

-- Write DIR/inspect.js for a compared Run; returns its path, or nil when
-- the image is larger than max_pixels.
function inspector.write(run, dir, key)
  local est, ref, se, region = run:image("visibility"), run:image("reference"), run:image("stderr"), run:image("region")
  local w, h, channels = est:size()
  if w * h > inspector.max_pixels then return nil end
  local bytes = {}
  for y = 1, h do
    for x = 1, w do
      local e = mean_at(est, x, y, channels)
      local code = math.tointeger(region:get(x, y, 1)) + ((e ~= e or e == math.huge or e == -math.huge) and 128 or 0)
      bytes[#bytes + 1] = string.pack("<I2I2I2B", u16(e), u16(mean_at(ref, x, y, channels)),
                                      u16(mean_at(se, x, y, channels)), code)
    end
  end
  local path = dir .. "/inspect.js"
  sl.write_file(path, string.format('(window.SL_INSPECT = window.SL_INSPECT || {})["%s"] = {w: %d, h: %d, data: "%s"};\n',
                                    key, w, h, base64(table.concat(bytes))))
  return path
end

-- The page's part: the overlay and its script. Images with data-inspect
-- (the configuration's key) open it; data-ref, data-est and data-err name
-- the three images it flips between. With #inspect-test=X,Y the page clicks
-- the first configuration's image, presses f twice, moves the cursor to
-- pixel (X, Y) and writes what it read into #inspect-result (the browser
-- test, tests/lua/run.sh).
inspector.html = [[
<div id="inspector" style="display:none; position:fixed; inset:0; background:rgba(20,20,20,.92); color:#eee;
     z-index:10; overflow:auto; font: 13px monospace;">
  <div style="position:sticky; top:0; background:#222; padding:6px 10px;">
    <b id="inspect-title"></b> — <span id="inspect-layer"></span> · zoom <span id="inspect-zoom"></span>x ·
    keys: <b>f</b>/space flip (reference, estimate, signed error), <b>+</b>/<b>-</b> zoom, <b>Esc</b> close
    <div id="inspect-readout">move the cursor over the image</div>
  </div>
  <canvas id="inspect-canvas" style="margin:10px; cursor:crosshair; image-rendering:pixelated;"></canvas>
</div>
<p id="inspect-result" hidden></p>
<script>
(function () {
  var D = window.SL_INSPECT = window.SL_INSPECT || {};
  var NAMES = ["not scored", "penumbra", "umbra", "lit", "terminator"];
  var box = document.getElementById("inspector"), canvas = document.getElementById("inspect-canvas");
  var state = null, on_opened = null; // on_opened: the browser test's continuation
  function load(key, done) {
    if (D[key]) return done(D[key]);
    var s = document.createElement("script");
    s.src = "images/" + key + "/inspect.js";
    s.onload = function () { done(D[key]); };
    s.onerror = function () { document.getElementById("inspect-readout").textContent = "no pixel data for " + key; };
    document.head.appendChild(s);
  }
  function decode(d) {
    if (!d.bytes) {
      var bin = atob(d.data), b = new Uint8Array(bin.length);
      for (var i = 0; i < bin.length; i++) b[i] = bin.charCodeAt(i);
      d.bytes = b;
    }
    return d;
  }
  function pixel(d, x, y) {
    var b = d.bytes, o = 7 * (y * d.w + x);
    function u(k) { return (b[o + k] | (b[o + k + 1] << 8)) / 65535; }
    var code = b[o + 6];
    return { est: code & 128 ? NaN : u(0), ref: u(2), se: u(4), region: NAMES[code & 127] || "?" };
  }
  function draw() {
    var d = state.data, img = state.images[state.layer];
    canvas.width = d.w * state.zoom; canvas.height = d.h * state.zoom;
    var ctx = canvas.getContext("2d");
    ctx.imageSmoothingEnabled = false;
    ctx.drawImage(img, 0, 0, canvas.width, canvas.height);
    document.getElementById("inspect-layer").textContent = state.names[state.layer];
    document.getElementById("inspect-zoom").textContent = state.zoom;
  }
  function open(el, done) {
    var key = el.getAttribute("data-inspect");
    load(key, function (d) {
      var srcs = [el.getAttribute("data-ref"), el.getAttribute("data-est"), el.getAttribute("data-err")], n = 0;
      state = { key: key, data: decode(d), layer: 0, names: ["reference", "estimate", "signed error"], images: [],
                zoom: Math.max(1, Math.floor(Math.min(1100 / d.w, 700 / d.h))), visited: ["reference"] };
      srcs.forEach(function (src, i) {
        var im = new Image();
        im.onload = function () { if (++n === 3) { draw(); if (done) done(); } };
        im.src = src;
        state.images[i] = im;
      });
      document.getElementById("inspect-title").textContent = el.getAttribute("data-label");
      box.style.display = "block";
    });
  }
  function flip() {
    state.layer = (state.layer + 1) % 3;
    state.visited.push(state.names[state.layer]);
    draw();
  }
  function read(clientX, clientY) {
    var r = canvas.getBoundingClientRect();
    var x = Math.floor((clientX - r.left) / state.zoom), y = Math.floor((clientY - r.top) / state.zoom);
    if (x < 0 || y < 0 || x >= state.data.w || y >= state.data.h) return null;
    var p = pixel(state.data, x, y);
    document.getElementById("inspect-readout").textContent = "pixel (" + x + ", " + y + "): estimate " +
      p.est.toFixed(5) + ", reference " + p.ref.toFixed(5) + " ± " + p.se.toFixed(5) + " (std error), class " +
      p.region;
    p.x = x; p.y = y;
    return p;
  }
  canvas.addEventListener("mousemove", function (e) { read(e.clientX, e.clientY); });
  document.addEventListener("keydown", function (e) {
    if (!state || box.style.display === "none") return;
    if (e.key === "f" || e.key === " ") { flip(); e.preventDefault(); }
    else if (e.key === "+" || e.key === "=") { state.zoom = Math.min(64, state.zoom + 1); draw(); }
    else if (e.key === "-") { state.zoom = Math.max(1, state.zoom - 1); draw(); }
    else if (e.key === "Escape") box.style.display = "none";
  });
  document.querySelectorAll("img[data-inspect]").forEach(function (el) {
    el.style.cursor = "zoom-in";
    el.addEventListener("click", function () { open(el, on_opened); });
  });
  // the browser test: open, flip twice, read a pixel, and the RMSE over the scored pixels
  var m = /^#inspect-test=(\d+),(\d+)$/.exec(location.hash);
  if (m) {
    var first = document.querySelector("img[data-inspect]");
    if (!first) return;
    on_opened = function () {
      ["f", "f"].forEach(function (k) { document.dispatchEvent(new KeyboardEvent("keydown", { key: k })); });
      window.scrollTo(0, 0);
      var r = canvas.getBoundingClientRect(), x = +m[1], y = +m[2];
      canvas.dispatchEvent(new MouseEvent("mousemove", { clientX: r.left + (x + 0.5) * state.zoom,
                                                         clientY: r.top + (y + 0.5) * state.zoom }));
      var p = read(r.left + (x + 0.5) * state.zoom, r.top + (y + 0.5) * state.zoom), d = state.data, s = 0, n = 0;
      for (var i = 0; i < d.w * d.h; i++) {
        var q = pixel(d, i % d.w, Math.floor(i / d.w));
        if (q.region !== "not scored" && q.est === q.est) { s += (q.est - q.ref) * (q.est - q.ref); n++; }
      }
      var out = document.getElementById("inspect-result");
      out.setAttribute("data-key", state.key);
      out.setAttribute("data-layers", state.visited.join(","));
      out.setAttribute("data-shown", state.names[state.layer]);
      out.setAttribute("data-readout", document.getElementById("inspect-readout").textContent);
      out.setAttribute("data-x", p.x); out.setAttribute("data-y", p.y);
      out.setAttribute("data-est", p.est); out.setAttribute("data-ref", p.ref); out.setAttribute("data-se", p.se);
      out.setAttribute("data-region", p.region);
      out.setAttribute("data-rmse", Math.sqrt(s / n));
    };
    first.click();
  }
})();
</script>
]]

return inspector
