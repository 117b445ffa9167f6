// Opens a viewer page (bimart view) in headless Chromium from a file:// URL and checks it:
//   node viewer_check.js PAGE.html SCREENSHOT.png [CHROMIUM]
// no console errors or page errors, no request other than the page itself (data: and
// blob: URLs are in-page), the frame counter advances while playing, the sample switcher
// works, and a flat-colour pass shows both hands and the object (pixel counts); with marks of
// a directed run, a pinned frame shows its pin and a free frame none. Then a screenshot. Exits 1 on any failure.
const path = require('path');
const puppeteer = require('puppeteer-core');

async function main() {
  const [page_file, shot, chromium = '/usr/bin/chromium'] = process.argv.slice(2);
  const url = 'file://' + path.resolve(page_file);
  const browser = await puppeteer.launch({
    executablePath: chromium, headless: true,
    args: ['--no-sandbox', '--use-angle=swiftshader', '--enable-unsafe-swiftshader', '--window-size=1000,700'],
  });
  const failures = [];
  try {
    const page = await browser.newPage();
    await page.setViewport({ width: 1000, height: 700 });
    const errors = [], requests = [];
    page.on('console', (m) => { if (m.type() === 'error') errors.push(m.text()); });
    page.on('pageerror', (e) => errors.push(String(e)));
    page.on('request', (r) => {
      const u = r.url();
      if (u !== url && !u.startsWith('data:') && !u.startsWith('blob:')) requests.push(u);
    });
    await page.goto(url, { waitUntil: 'load' });
    await page.waitForFunction(() => window.bimartViewer && window.bimartViewer.ready, { timeout: 60000 });
    const f0 = await page.evaluate(() => window.bimartViewer.frame());
    await new Promise((r) => setTimeout(r, 1500));
    const f1 = await page.evaluate(() => window.bimartViewer.frame());
    const shown = await page.evaluate(() => window.bimartViewer.framesShown());
    console.log(`frames: ${f0} then ${f1} after 1.5 s, ${shown} frames shown`);
    if (!(shown > 3 && f1 !== f0)) failures.push('the frame counter did not advance');
    const text = await page.$eval('#frame', (e) => e.textContent);
    if (!/^frame \d+ \/ \d+$/.test(text)) failures.push('frame counter text: ' + text);

    const samples = await page.evaluate(() => window.bimartViewer.samples);
    if (samples > 1) {
      await page.evaluate(() => window.bimartViewer.select(1));
      const name = await page.$eval('#sample', (e) => e.options[e.selectedIndex].text);
      console.log(`sample switcher: ${samples} samples, now '${name}'`);
      await page.evaluate(() => window.bimartViewer.select(0));
    }
    await page.evaluate(() => { window.bimartViewer.play(false); window.bimartViewer.setFrame(Math.floor(window.bimartViewer.frame())); });
    const cover = await page.evaluate(() => window.bimartViewer.coverage());
    console.log(`pixels: left hand ${cover.left}, right hand ${cover.right}, object ${cover.object} of ${cover.pixels}`);
    for (const k of ['left', 'right', 'object'])
      if (!(cover[k] > 0.002 * cover.pixels)) failures.push(`the ${k} covers too few pixels (${cover[k]})`);
    // Toggling a hand off removes its pixels.
    await page.click('#show-left');
    const hidden = await page.evaluate(() => window.bimartViewer.coverage());
    await page.click('#show-left');
    if (hidden.left !== 0) failures.push(`left hand toggled off still covers ${hidden.left} pixels`);
    // A directed run's marks (bimart view --hands): at a pinned frame the pin is shown and
    // named under the timeline; at a frame no mark covers, nothing is.
    const marks = await page.evaluate(() => JSON.parse(document.getElementById('bimart-data').textContent).samples[0].marks || []);
    if (marks.length) {
      const pin = marks.find((m) => m.wrists);
      const covered = (f) => marks.some((m) => f >= m.first && f <= m.last);
      const frames = await page.evaluate(() => JSON.parse(document.getElementById('bimart-data').textContent).samples[0].frames);
      let free = -1;
      for (let f = 0; f < frames && free < 0; ++f) if (!covered(f)) free = f;
      if (free >= 0) {
        await page.evaluate((f) => window.bimartViewer.setFrame(f), free);
        const at = await page.evaluate(() => window.bimartViewer.marksShown());
        console.log(`marks at free frame ${free}: ${JSON.stringify(at)}`);
        if (at.pins !== 0 || !/free/.test(at.text)) failures.push('a frame without marks shows ' + JSON.stringify(at));
      }
      if (pin) {
        await page.evaluate((f) => window.bimartViewer.setFrame(f), pin.first);
        const at = await page.evaluate(() => window.bimartViewer.marksShown());
        console.log(`marks at pinned frame ${pin.first}: ${JSON.stringify(at)}`);
        if (at.pins < 1 || !at.text.includes(pin.label)) failures.push('the pinned frame shows ' + JSON.stringify(at));
      }
      const strip = await page.$eval('#marks', (e) => !e.hidden && e.getBoundingClientRect().height > 20);
      if (!strip) failures.push('the timeline of marks is not shown');
    }
    await new Promise((r) => setTimeout(r, 200));
    await page.screenshot({ path: shot });
    console.log(`console errors: ${errors.length}, network requests: ${requests.length}, screenshot ${shot}`);
    for (const e of errors) failures.push('console: ' + e);
    for (const r of requests) failures.push('request: ' + r);
  } finally {
    await browser.close();
  }
  for (const f of failures) console.log('FAIL ' + f);
  process.exit(failures.length ? 1 : 0);
}
main().catch((e) => { console.error(e); process.exit(2); });
