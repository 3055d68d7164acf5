// Browser test of `bodypoint view`: writes pages for the thesis scene, the two-centres scene and a
// comparison, opens each from disk in Debian's Chromium (headless, driven by playwright-core, no
// network), and checks: no console error, a first frame, a canvas that is not blank, a body that
// moves on screen when the time slider moves. Screenshots and measurements go to --artifacts.
//
//   node browser_test.mjs --bodypoint build/bin/bodypoint --artifacts build/viewer-artifacts [--shot FILE.png]
// --shot also saves the comparison page at t_end/2 (README's screenshot) to FILE.png.
// Exit 0: passed; 1: failed; 77: Chromium or playwright-core missing (ctest counts it as skipped).
import { execFileSync } from 'node:child_process';
import { copyFileSync, existsSync, mkdirSync, statSync, writeFileSync } from 'node:fs';
import path from 'node:path';
import { fileURLToPath, pathToFileURL } from 'node:url';

const here = path.dirname(fileURLToPath(import.meta.url));
const repo = path.resolve(here, '../../..');
const arg = (name, fallback) => {
  const i = process.argv.indexOf(name);
  return i >= 0 ? process.argv[i + 1] : fallback;
};
const bodypoint = path.resolve(arg('--bodypoint', path.join(repo, 'build/bin/bodypoint')));
const artifacts = path.resolve(arg('--artifacts', path.join(repo, 'build/viewer-artifacts')));
const shot = arg('--shot', null);
const chromiumPath = process.env.CHROMIUM || '/usr/bin/chromium';

// A blank canvas (one clear colour; header and panels are HTML above it) has a luminance deviation of 0
// and no pixel off the background. The three pages' full views (thin trails, centres, a body, arrows)
// measured std 3.8..4.9 and 0.21..0.31 % of the pixels; the bounds are a fifth of the smallest.
const MIN_LUMINANCE_STD = 0.75;
const MIN_NON_BACKGROUND = 0.0004;
// Moving the slider from t = 0 to t = t_end/2 moves the body across the screen (hundreds of pixels on
// the thesis scene); the body's pixels must change by more than antialiasing noise (< 1 of 255).
const MIN_BODY_SHIFT_PX = 20;
const MIN_PIXEL_CHANGE = 8;
const BODY_BOX_PX = 6;  // half-width of the box around the body's centre that is compared
const TIMEOUT_MS = 60000;

let playwright;
try {
  playwright = await import('playwright-core');
} catch {
  console.log('SKIP: playwright-core is not installed (scripts/setup.sh runs npm ci in experiments/viewer)');
  process.exit(77);
}
if (!existsSync(chromiumPath)) {
  console.log(`SKIP: no Chromium at ${chromiumPath} (scripts/setup.sh installs Debian's chromium)`);
  process.exit(77);
}
mkdirSync(artifacts, { recursive: true });

const pages = [
  // The thesis page asks for an event (the body crossing x = 0 near its closest approach): one mark per hit.
  { name: 'thesis', args: ['--event', 'x=0'], events: true },
  { name: 'two-centres', args: ['--scene', path.join(repo, 'scenes/two-centres.toml'), '--method', 'logh-y4', '--h', '0.01', '--t-end', '60'] },
  { name: 'compare', args: ['--Kz', '0.1', '--d', '0.05', '--t-end', '80', '--method', 'thesis-verlet', '--h', '1e-3',
    '--compare', 'logh-kl6', '--compare-h', '0.05'] },
];

const failures = [];
const report = {};
const browser = await playwright.chromium.launch({
  executablePath: chromiumPath,
  headless: true,
  args: ['--no-sandbox', '--use-angle=swiftshader', '--enable-unsafe-swiftshader', '--ignore-gpu-blocklist'],
});
try {
  for (const p of pages) {
    const file = path.join(artifacts, `view-${p.name}.html`);
    execFileSync(bodypoint, ['view', ...p.args, '--out', file], { stdio: 'pipe' });
    const result = { bytes: statSync(file).size };
    const page = await browser.newPage({ viewport: { width: 1280, height: 800 } });
    const errors = [];
    page.on('console', (m) => { if (m.type() === 'error') errors.push(m.text()); });
    page.on('pageerror', (e) => errors.push(String(e)));
    page.on('request', (r) => { if (!r.url().startsWith('file:') && !r.url().startsWith('data:') && !r.url().startsWith('blob:')) errors.push(`network request: ${r.url()}`); });
    await page.goto(pathToFileURL(file).href);
    await page.waitForFunction(() => window.bodypointViewer && window.bodypointViewer.frames > 2, null, { timeout: TIMEOUT_MS });
    // Every track marks its located closest approach; a single Coulomb centre adds two asymptotes per track.
    const marks = await page.evaluate(() => window.bodypointViewer.marks);
    const tracks = await page.evaluate(() => window.bodypointViewer.tracks);
    result.marks = marks;
    if (marks.closest !== tracks) failures.push(`${p.name}: ${marks.closest} closest-approach marks for ${tracks} tracks`);
    if (p.name !== 'two-centres' && marks.asymptotes !== 2 * tracks)
      failures.push(`${p.name}: ${marks.asymptotes} asymptote lines for ${tracks} tracks`);
    // The asked events: one mark per located hit, and the header names the located closest approach.
    const hits = await page.evaluate(() => JSON.parse(document.getElementById('bodypoint-data').textContent)
      .runs.flatMap((r) => r.bodies.flatMap((b) => b.events)).length);
    if (marks.events !== hits || (p.events && hits === 0))
      failures.push(`${p.name}: ${marks.events} event marks for ${hits} located hits`);
    const header = await page.evaluate(() => document.getElementById('bp-header').textContent);
    if (!/r_min \S+ at t=/.test(header)) failures.push(`${p.name}: the header does not state the located r_min`);

    // Frame rate while playing, then pause for the still checks.
    const fps = await page.evaluate(async () => {
      const v = window.bodypointViewer, f0 = v.frames, t0 = performance.now();
      await new Promise((r) => setTimeout(r, 3000));
      return (v.frames - f0) / ((performance.now() - t0) / 1000);
    });
    result.fps = Math.round(fps * 10) / 10;
    await page.evaluate(() => window.bodypointViewer.pause());

    const setSlider = async (value) => {
      await page.evaluate((v) => {
        const s = document.getElementById('bp-time');
        s.value = String(v);
        s.dispatchEvent(new Event('input'));
      }, value);
      const f = await page.evaluate(() => window.bodypointViewer.frames);
      await page.waitForFunction((f0) => window.bodypointViewer.frames > f0 + 2, f, { timeout: TIMEOUT_MS });
    };
    await setSlider(0);
    const stats = await page.evaluate(() => window.bodypointViewer.canvasStats());
    result.stats = stats;
    if (!(stats.std > MIN_LUMINANCE_STD && stats.nonBackground > MIN_NON_BACKGROUND))
      failures.push(`${p.name}: the canvas looks blank (luminance std ${stats.std.toFixed(2)}, ${(100 * stats.nonBackground).toFixed(3)} % off the background)`);
    const before = await page.evaluate(() => window.bodypointViewer.bodyScreen(0));
    await page.evaluate(() => window.bodypointViewer.snapshot());
    await page.screenshot({ path: path.join(artifacts, `view-${p.name}-start.png`) });
    await setSlider(5000);
    const after = await page.evaluate(() => window.bodypointViewer.bodyScreen(0));
    const shift = Math.hypot(after[0] - before[0], after[1] - before[1]);
    const changeOld = await page.evaluate(([x, y, r]) => window.bodypointViewer.diffAround(x, y, r), [...before, BODY_BOX_PX]);
    const changeNew = await page.evaluate(([x, y, r]) => window.bodypointViewer.diffAround(x, y, r), [...after, BODY_BOX_PX]);
    await page.screenshot({ path: path.join(artifacts, `view-${p.name}-middle.png`) });
    Object.assign(result, { shift_px: Math.round(shift), pixel_change_old: changeOld, pixel_change_new: changeNew });
    if (!(shift > MIN_BODY_SHIFT_PX)) failures.push(`${p.name}: the body moved ${shift.toFixed(1)} px on screen when the slider moved`);
    if (!(changeOld > MIN_PIXEL_CHANGE && changeNew > MIN_PIXEL_CHANGE))
      failures.push(`${p.name}: the pixels at the body's old and new places changed by ${changeOld.toFixed(1)} and ${changeNew.toFixed(1)} (of 255)`);
    if (errors.length) failures.push(`${p.name}: console errors: ${errors.join(' | ')}`);
    report[p.name] = result;
    console.log(`${p.name}: ${(result.bytes / 1e3).toFixed(0)} kB, ${result.fps} frames/s, canvas std ${stats.std.toFixed(1)}, ` +
      `${(100 * stats.nonBackground).toFixed(2)} % drawn, body moved ${result.shift_px} px (pixel change ${changeOld.toFixed(0)}/${changeNew.toFixed(0)})`);
    await page.close();
  }
} finally {
  await browser.close();
}
writeFileSync(path.join(artifacts, 'report.json'), JSON.stringify(report, null, 2) + '\n');
if (shot) copyFileSync(path.join(artifacts, 'view-compare-middle.png'), path.resolve(shot));
if (failures.length) {
  for (const f of failures) console.error(`FAIL ${f}`);
  process.exit(1);
}
console.log(`PASS: ${pages.length} pages; screenshots in ${artifacts}`);
