// A strip chart of the last `span` samples of two series on one canvas, each scaled to its own
// maximum: the tick's compute time (µs) and |force| (N).
export class StripChart {
  constructor(canvas, span = 600) {
    this.ctx = canvas.getContext('2d');
    this.canvas = canvas;
    this.span = span;
    this.series = [{ color: '#6cf', data: [] }, { color: '#fc6', data: [] }];
  }

  push(tickUs, forceN) {
    [tickUs, forceN].forEach((v, i) => {
      const d = this.series[i].data;
      d.push(v);
      if (d.length > this.span) d.shift();
    });
  }

  draw() {
    const { ctx, canvas } = this;
    const w = canvas.width, h = canvas.height;
    ctx.fillStyle = '#15171b';
    ctx.fillRect(0, 0, w, h);
    ctx.font = '11px monospace';
    this.series.forEach((s, i) => {
      const max = Math.max(1e-9, ...s.data);
      ctx.strokeStyle = s.color;
      ctx.beginPath();
      s.data.forEach((v, k) => {
        const x = (k / (this.span - 1)) * w;
        const y = h - 4 - (v / max) * (h - 20);
        if (k === 0) ctx.moveTo(x, y); else ctx.lineTo(x, y);
      });
      ctx.stroke();
      ctx.fillStyle = s.color;
      ctx.fillText(`max ${max.toPrecision(3)}`, 4 + i * 120, 12);
    });
  }
}
