// The frame times of a `kinergy view` page playing in real time in headless Chromium: opens
// PAGE, lets it play for SECONDS (default 10), and prints what the page measured of itself
// (data-frame-ms: the mean time between drawn frames, data-frame-ms-p95, data-rendered-frames).
//
//   npm install --prefix /tmp/pw playwright-core@1.64.1   # once; nothing is committed
//   NODE_PATH=/tmp/pw/node_modules node tools/view-frames.mjs view.html [SECONDS]
//
// Chromium is Debian's (/usr/bin/chromium, or KINERGY_CHROMIUM), with software WebGL.
import { createRequire } from 'node:module';
import { pathToFileURL } from 'node:url';
import path from 'node:path';

const require = createRequire(import.meta.url);
const { chromium } = require('playwright-core');
const [page, seconds = '10'] = process.argv.slice(2);
if (!page) {
  console.error('usage: node tools/view-frames.mjs PAGE.html [SECONDS]');
  process.exit(2);
}
const browser = await chromium.launch({
  executablePath: process.env.KINERGY_CHROMIUM || '/usr/bin/chromium',
  args: ['--no-sandbox', '--use-angle=swiftshader', '--enable-unsafe-swiftshader',
    '--disable-background-networking', '--disable-component-update', '--disable-sync'],
});
const tab = await browser.newPage({ viewport: { width: Number(process.env.VIEW_W || 1280), height: Number(process.env.VIEW_H || 800) } });
await tab.goto(pathToFileURL(path.resolve(page)).href);
await tab.waitForFunction(() => document.body.dataset.ready === '1');
// Only the intervals while playing count: the page keeps the last 600.
await tab.waitForTimeout(Number(seconds) * 1000);
const d = await tab.evaluate(() => ({ ...document.body.dataset }));
console.log(JSON.stringify({
  frame_ms: Number(d.frameMs), frame_ms_p95: Number(d.frameMsP95),
  rendered_frames: Number(d.renderedFrames), render_ms: Number(d.renderMs), clips: d.clips, frames: d.frames, time_s: Number(d.time),
}));
await browser.close();
