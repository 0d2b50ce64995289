// Paths and the native reference runs the tests compare with.
import { readFileSync } from 'node:fs';
import { join } from 'node:path';

export const HERE = new URL('.', import.meta.url).pathname;
export const WWW = join(HERE, '..', 'www');
export const OUT = join(HERE, 'out');

/**
 * The native run `granbed-cli granule` wrote into the directory named by the
 * environment variable `name` (run.sh sets it): its summary.json and
 * force_displacement.csv.
 */
export function native(name) {
  const dir = process.env[name];
  if (!dir) throw new Error(`${name} is not set: run the tests with wasm/browser-test/run.sh`);
  return {
    summary: JSON.parse(readFileSync(join(dir, 'summary.json'), 'utf8')),
    csv: readFileSync(join(dir, 'force_displacement.csv'), 'utf8'),
  };
}
