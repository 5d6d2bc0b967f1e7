// uPlot chart of a cam over its master: position, velocity, acceleration and jerk, each on its
// own scale (the server's sampled values: it is the one source of the cam's math). The element
// carries `data-samples` and `data-series` for the tests.
import uPlot from 'uplot';

export const CAM_COLORS = ['#1363c6', '#2b8a3e', '#d9480f', '#ae3ec9'];

export class CamChart {
  private u: uPlot;
  private ro: ResizeObserver | null = null;

  constructor(el: HTMLElement, columns: string[], rows: number[][]) {
    const x = rows.map((r) => r[0]);
    const names = columns.slice(1);
    const scales: uPlot.Scales = { x: { time: false } };
    const axes: uPlot.Axis[] = [{ label: 'master', stroke: '#4a5563', grid: { stroke: '#e6e9ee' }, ticks: { stroke: '#c9cfd6' } }];
    names.forEach((n, i) => {
      scales[n] = { auto: true };
      axes.push({
        scale: n,
        label: n,
        side: i % 2 === 0 ? 3 : 1,
        stroke: CAM_COLORS[i],
        grid: { show: i === 0, stroke: '#eef0f3' },
        ticks: { stroke: '#c9cfd6' },
        size: 64,
      });
    });
    const width = () => Math.max(320, el.clientWidth || 640);
    const opts: uPlot.Options = {
      width: width(),
      height: 320,
      scales,
      axes,
      legend: { live: true },
      cursor: { drag: { x: true, y: false } },
      series: [{ label: 'master' }, ...names.map((n, i) => ({ label: n, scale: n, stroke: CAM_COLORS[i], width: 1.5 }))],
    };
    const data: uPlot.AlignedData = [x, ...names.map((_, i) => rows.map((r) => r[i + 1]))];
    this.u = new uPlot(opts, data, el);
    el.dataset.samples = String(x.length);
    el.dataset.series = names.join(',');
    if (typeof ResizeObserver !== 'undefined') {
      this.ro = new ResizeObserver(() => this.u.setSize({ width: width(), height: 320 }));
      this.ro.observe(el);
    }
  }

  destroy(): void {
    this.ro?.disconnect();
    this.u.destroy();
  }
}
