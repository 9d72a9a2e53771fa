// The timeline of a time-dependent design (a `[time]` section with formulas in t, a rig, or a
// morph): play, pause, scrub, loop. Each shown time is the design at t re-solved by the server;
// while one time is being solved only the newest waits (the channel coalesces), so playback
// drops frames rather than falling behind.

const $ = (id) => document.getElementById(id);

export class Timeline {
  // `channel` sends `{ t }` bodies and shows their frames.
  constructor(channel) {
    this.channel = channel;
    this.time = null; // the scene's `time`
    this.playing = false;
    this.scrubbing = false;
    this.shown = 0; // frames shown while playing
    this.wanted = null; // the time asked for last
    $('t-play').onclick = () => (this.playing ? this.pause() : this.play());
    const slider = $('t-slider');
    slider.addEventListener('pointerdown', () => { this.scrubbing = true; this.pause(); });
    slider.addEventListener('input', (ev) => {
      this.pause();
      this.ask(Number(slider.value), ev.timeStamp);
    });
    slider.addEventListener('change', () => { this.scrubbing = false; });
  }

  // Follows the scene: shown only for a time-dependent design.
  update(scene) {
    const box = $('timeline');
    this.time = scene.time;
    if (!this.time) {
      this.pause();
      box.hidden = true;
      $('frozen').textContent = scene.frozen_at != null
        ? `Edited at t = ${scene.frozen_at.toFixed(3)} s: a still design now (load its file again to play it).`
        : '';
      return;
    }
    box.hidden = false;
    $('frozen').textContent = '';
    const { start, end, t } = this.time;
    const slider = $('t-slider');
    slider.min = start;
    slider.max = end;
    slider.step = (end - start) / 1000;
    if (!this.scrubbing) slider.value = t;
    if (this.loaded !== scene.file) {
      this.loaded = scene.file;
      $('t-loop').checked = this.time.loop;
    }
    const eps = this.time.epsilon == null ? '' : `, ε = ${this.time.epsilon.toFixed(3)}`;
    $('t-value').textContent = `t = ${t.toFixed(3)} s${eps}`;
    $('t-range').textContent = `[${start}, ${end}] s, ${this.time.frames} frames${this.time.loop ? ', periodic' : ''}`;
    if (this.playing) this.shown += 1;
  }

  ask(t, at) {
    this.wanted = t;
    this.channel.push(() => ({ t: this.wanted }), at);
  }

  play() {
    if (!this.time || this.playing) return;
    const { start, end } = this.time;
    let t0 = this.time.t;
    if (t0 >= end && !$('t-loop').checked) t0 = start;
    this.playing = true;
    this.shown = 0;
    const wall0 = performance.now();
    $('t-play').textContent = '❚❚ Pause';
    const tick = (now) => {
      if (!this.playing || !this.time) return;
      const span = end - start;
      let t = t0 + (now - wall0) / 1000;
      if (t > end) {
        if ($('t-loop').checked) t = start + ((t - start) % span);
        else { t = end; this.pause(); }
      }
      const fps = (this.shown * 1000) / Math.max(now - wall0, 1);
      $('t-rate').textContent = `${fps.toFixed(1)} frames/s`;
      this.ask(t, now);
      if (this.playing) requestAnimationFrame(tick);
    };
    requestAnimationFrame(tick);
  }

  pause() {
    this.playing = false;
    $('t-play').textContent = '▶ Play';
  }
}
