// Dolos (its library, the engine of its command line) on one folder of student files, with the
// starter as the ignored template (the CLI's -i) and fingerprints in more than half the files
// ignored (the CLI's -M 0.5). Prints `a,b,similarity` for every pair, students by file number.
import { Dolos } from "@dodona/dolos-lib";
import fs from "fs";
import path from "path";

const [folder, template] = process.argv.slice(2);
const files = fs.readdirSync(folder).filter(f => f.endsWith(".rs")).sort().map(f => path.join(folder, f));
const dolos = new Dolos({ language: "rust", maxFingerprintPercentage: 0.5 });
const report = await dolos.analyzePaths(files, template);
const number = file => parseInt(path.basename(file.path).match(/\d+/)[0], 10);
for (const pair of report.allPairs()) {
  const [a, b] = [number(pair.leftFile), number(pair.rightFile)].sort((x, y) => x - y);
  console.log(`${a},${b},${pair.similarity}`);
}
