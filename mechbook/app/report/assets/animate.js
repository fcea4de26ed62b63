// mechbook report: the bodies of a simulated motion, drawn on a canvas from the frames the
// page carries (JSON in a <script type="application/json">). Offline; no library.
(function () {
  "use strict";
  const COLOURS = ["#1f77b4", "#d62728", "#2ca02c", "#9467bd", "#ff7f0e", "#8c564b"];
  function setup(figure) {
    figure.dataset.ready = "1";                  // set up once (a notebook runs this again)
    const data = JSON.parse(figure.querySelector("script.motion").textContent);
    const canvas = figure.querySelector("canvas");
    const button = figure.querySelector("button");
    const label = figure.querySelector(".time");
    const ctx = canvas.getContext("2d");
    const [x0, x1, y0, y1] = data.box;
    const scale = Math.min(canvas.width / (x1 - x0), canvas.height / (y1 - y0));
    const ox = (canvas.width - scale * (x1 - x0)) / 2, oy = (canvas.height - scale * (y1 - y0)) / 2;
    const px = (p) => [ox + (p[0] - x0) * scale, canvas.height - oy - (p[1] - y0) * scale];
    const masses = data.bodies.map((b) => Math.abs(b.mass) || 1);
    const heaviest = Math.max(...masses);
    let frame = 0, playing = true, last = 0;
    function spring(a, b) {
      const [ax, ay] = px(a), [bx, by] = px(b);
      const n = 12, dx = (bx - ax) / n, dy = (by - ay) / n, len = Math.hypot(dx, dy) || 1;
      const nx = -dy / len * 5, ny = dx / len * 5;
      ctx.beginPath(); ctx.moveTo(ax, ay);
      for (let i = 1; i < n; i++) {
        const s = i % 2 ? 1 : -1;
        ctx.lineTo(ax + dx * i + s * nx, ay + dy * i + s * ny);
      }
      ctx.lineTo(bx, by); ctx.strokeStyle = "#888"; ctx.lineWidth = 1; ctx.stroke();
    }
    function at(end) {                         // a body, a point moving with one, or fixed
      if (typeof end === "number") return data.bodies[end].path[frame];
      return end.path ? end.path[frame] : end;
    }
    function link(a, b) {                        // a rod: a thick dark line
      const [ax, ay] = px(a), [bx, by] = px(b);
      ctx.beginPath(); ctx.moveTo(ax, ay); ctx.lineTo(bx, by);
      ctx.strokeStyle = "#333"; ctx.lineWidth = 3; ctx.lineCap = "round"; ctx.stroke();
    }
    function pivot(p) {          // a fixed hinge: a triangle on hatching, away from its body
      const [x, y] = px(p.at);
      const sx = p.side[0], sy = -p.side[1], nx = -sy, ny = sx;  // screen y points down
      const bx = x + 11 * sx, by = y + 11 * sy;
      ctx.beginPath(); ctx.moveTo(x, y); ctx.lineTo(bx + 7 * nx, by + 7 * ny);
      ctx.lineTo(bx - 7 * nx, by - 7 * ny); ctx.closePath();
      ctx.fillStyle = "#fff"; ctx.fill(); ctx.strokeStyle = "#333"; ctx.lineWidth = 1.5;
      ctx.stroke(); ctx.beginPath();
      for (let i = -9; i <= 9; i += 4.5) {
        ctx.moveTo(bx + i * nx, by + i * ny);
        ctx.lineTo(bx + i * nx + 5 * sx - 3 * nx, by + i * ny + 5 * sy - 3 * ny);
      }
      ctx.lineWidth = 1; ctx.stroke();
    }
    function outline(o) {                        // a body's shape, turned as it turns
      const c = data.bodies[o.body].path[frame];
      const r = o.turns ? o.turns[frame] : null;
      const place = (p) => r ? [c[0] + r[0] * p[0] + r[1] * p[1] + r[2] * p[2],
                                c[1] + r[3] * p[0] + r[4] * p[1] + r[5] * p[2]]
                             : [c[0] + p[0], c[1] + p[1]];
      ctx.strokeStyle = COLOURS[o.body % COLOURS.length]; ctx.lineWidth = 1.6;
      o.lines.forEach((line, i) => {
        if (o.axes) ctx.strokeStyle = ["#d62728", "#2ca02c", "#1f77b4"][i % 3];
        ctx.beginPath();
        line.forEach((p, k) => {
          const [x, y] = px(place(p));
          if (k === 0) ctx.moveTo(x, y); else ctx.lineTo(x, y);
        });
        ctx.stroke();
      });
    }
    function draw() {
      ctx.clearRect(0, 0, canvas.width, canvas.height);
      data.bodies.forEach((b, k) => {            // the path so far, faint
        ctx.beginPath();
        for (let i = 0; i <= frame; i++) {
          const [x, y] = px(b.path[i]);
          if (i === 0) ctx.moveTo(x, y); else ctx.lineTo(x, y);
        }
        ctx.strokeStyle = COLOURS[k % COLOURS.length] + "55"; ctx.lineWidth = 1; ctx.stroke();
      });
      data.springs.forEach((s) => spring(at(s[0]), at(s[1])));
      (data.links || []).forEach((s) => link(at(s[0]), at(s[1])));
      (data.pivots || []).forEach(pivot);
      (data.outlines || []).forEach(outline);
      data.bodies.forEach((b, k) => {
        const [x, y] = px(b.path[frame]);
        const r = 4 + 6 * Math.cbrt(masses[k] / heaviest);
        ctx.beginPath(); ctx.arc(x, y, r, 0, 2 * Math.PI);
        ctx.fillStyle = COLOURS[k % COLOURS.length]; ctx.fill();
      });
      label.textContent = "t = " + data.t[frame].toFixed(2);
      figure.dataset.frame = frame;              // which frame is drawn (for the tests)
    }
    function tick(now) {
      if (playing && now - last > 40) {
        frame = (frame + 1) % data.t.length; last = now; draw();
      }
      window.requestAnimationFrame(tick);
    }
    button.addEventListener("click", () => {
      playing = !playing; button.textContent = playing ? "pause" : "play";
    });
    draw();
    window.requestAnimationFrame(tick);
  }
  document.querySelectorAll("figure.animation:not([data-ready])").forEach(setup);
})();
