// SPDX-License-Identifier: GPL-3.0-or-later
// Flamenco 3 job type "ReSTIR Render": renders a .blend with the ReSTIR engine in chunks of frames, one Blender
// process per chunk (`blender -b FILE -E RESTIR ... -s S -e E -a`). ReSTIR's temporal reuse carries history from
// frame to frame; a chunk that starts mid-animation rebuilds it by preroll (the engine renders the first sample pass
// of the frames before the chunk, unsaved). With preroll = -1 every chunk prerolls back to the job's first frame,
// and the frames equal a sequential render exactly; a preroll of N frames costs N sample passes per chunk and
// matches statistically once N reaches the confidence cap. Install: copy this file into the `scripts` folder next
// to the Flamenco Manager executable and restart the Manager (docs/USAGE.md, "Farm").

const JOB_TYPE = {
    label: "ReSTIR Render",
    description: "Render frames with the ReSTIR engine, in chunks, temporal history rebuilt by preroll",
    settings: [
        { key: "blender_cmd", type: "string", default: "{blender}", visible: "hidden" },
        { key: "blendfile", type: "string", required: true, visible: "web",
          description: "Path of the .blend file to render" },
        { key: "frames", type: "string", required: true, eval: "f'{C.scene.frame_start}-{C.scene.frame_end}'",
          description: "Frame range to render, e.g. '1-240' or '1-10, 20-30'" },
        { key: "chunk_size", type: "int32", default: 24, description: "Frames rendered by one task" },
        { key: "preroll", type: "int32", default: -1,
          description: "Frames prerolled before a chunk's first frame: -1 = back to the job's first frame " +
                       "(exactly the sequential result), N = at most N (statistically the same once N reaches " +
                       "the confidence cap)" },
        { key: "render_output_path", type: "string", subtype: "file_path", required: true,
          eval: "bpy.path.abspath(C.scene.render.filepath)",
          description: "Output path; '#' stands for the frame number's digits" },
        { key: "format", type: "string", required: true, eval: "C.scene.render.image_settings.file_format",
          visible: "web" },
    ],
};

// The contiguous pieces [start, end] of a chunk string such as "1-8" or "9,10,20-22".
function pieces(chunk) {
    return String(chunk).split(",").map((part) => {
        const ends = part.trim().split("-").map((x) => parseInt(x, 10));
        return [ends[0], ends[ends.length - 1]];
    });
}

function compileJob(job) {
    const settings = job.settings;
    const ranges = [].concat(...frameChunker(settings.frames, settings.chunk_size).map(pieces));
    const jobFirst = Math.min(...ranges.map((r) => r[0]));
    print("ReSTIR Render:", ranges.length, "tasks for frames", settings.frames);
    for (const [start, end] of ranges) {
        const chunk = start === end ? `${start}` : `${start}-${end}`;
        const back = start - jobFirst;  // frames of this job before the chunk
        const preroll = settings.preroll < 0 ? back : Math.min(settings.preroll, back);
        const task = author.Task(`render-${chunk}`, "blender");
        task.addCommand(author.Command("blender-render", {
            exe: settings.blender_cmd,
            exeArgs: "{blenderArgs}",
            argsBefore: [],
            blendfile: settings.blendfile,
            args: [
                "-E", "RESTIR",
                "--python-expr", `import bpy; bpy.context.scene.restir.preroll_frames = ${preroll}`,
                "-o", settings.render_output_path,
                "-F", settings.format,
                "-s", String(start), "-e", String(end), "-a",
            ],
        }));
        job.addTask(task);
    }
}
