// A small stand-in for Flamenco 3's job-authoring API (author.Task, author.Command, job.addTask, frameChunker,
// print), as documented for job compiler scripts: loads a job type file, compiles one job and prints its tasks as
// JSON on stdout. Usage: node flamenco_stub.js JOBTYPE.js 'SETTINGS_JSON'
const fs = require("fs");
const vm = require("vm");

function parseFrames(spec) {  // "1-10, 20-30" -> [1..10, 20..30]
    const frames = [];
    for (const part of String(spec).split(",")) {
        const [a, b] = part.trim().split("-").map((x) => parseInt(x, 10));
        for (let f = a; f <= (isNaN(b) ? a : b); f++) frames.push(f);
    }
    return frames;
}

function frameChunker(spec, size) {  // consecutive runs of at most `size` frames, as range strings
    const frames = parseFrames(spec);
    const chunks = [];
    for (let i = 0; i < frames.length; i += size) {
        const run = frames.slice(i, i + size);
        const parts = [];
        let lo = run[0], prev = run[0];
        for (const f of run.slice(1).concat([null])) {
            if (f !== null && f === prev + 1) { prev = f; continue; }
            parts.push(lo === prev ? `${lo}` : `${lo}-${prev}`);
            lo = prev = f;
        }
        chunks.push(parts.join(","));
    }
    return chunks;
}

const tasks = [];
const context = {
    print: (...args) => process.stderr.write(args.join(" ") + "\n"),
    frameChunker,
    author: {
        Task: (name, type) => {
            const task = { name, type, commands: [], addCommand(cmd) { this.commands.push(cmd); } };
            return task;
        },
        Command: (type, params) => ({ type, params }),
    },
    console,
};
vm.createContext(context);
vm.runInContext(fs.readFileSync(process.argv[2], "utf8"), context);
const settings = JSON.parse(process.argv[3]);
for (const s of vm.runInContext("JOB_TYPE", context).settings) {
    if (!(s.key in settings) && "default" in s) settings[s.key] = s.default;
}
const job = { settings, addTask: (task) => tasks.push(task) };
vm.runInContext("compileJob", context)(job);
process.stdout.write(JSON.stringify(tasks.map((t) => ({ name: t.name, type: t.type, commands: t.commands }))));
