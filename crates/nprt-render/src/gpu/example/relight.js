// A worked example of running an nprt export: every step nprt's own GPU frame path takes
// (nprt-net/src/gpu/frame/gpu_network.rs), in WebGPU. One block of rows: the example's G-buffer
// is small; a renderer cuts larger frames into blocks of at most 65,536 rows. Every size of the
// network and every kernel's parameters and workgroup size are read from export.json.

const status = document.getElementById('status');
const report = new URLSearchParams(location.search).has('report');

async function bytes(url) {
  const response = await fetch(url);
  if (!response.ok) throw new Error(`${url}: ${response.status} ${response.statusText}`);
  return response.arrayBuffer();
}
const json = async (url) => JSON.parse(new TextDecoder().decode(await bytes(url)));
const floats = async (url) => new Float32Array(await bytes(url));

async function main() {
  const exp = await json('../export.json');
  const weights = await floats('../' + exp.weights.file);
  const ex = await json('example.json');
  const gbuffer = await floats(ex.gbuffer.file);
  const light = await floats(ex.light.file);
  const reference = await floats(ex.reference.file);

  if (!navigator.gpu) throw new Error('this browser has no WebGPU');
  const adapter = await navigator.gpu.requestAdapter();
  if (!adapter) throw new Error('no WebGPU adapter');
  const device = await adapter.requestDevice({
    requiredLimits: {
      maxStorageBufferBindingSize: adapter.limits.maxStorageBufferBindingSize,
      maxBufferSize: adapter.limits.maxBufferSize,
    },
  });
  const STORAGE = GPUBufferUsage.STORAGE | GPUBufferUsage.COPY_SRC | GPUBufferUsage.COPY_DST;

  // Buffers: uploaded data, and room for `n` floats.
  const upload = (data) => {
    const buffer = device.createBuffer({ size: Math.max(16, data.byteLength), usage: STORAGE });
    device.queue.writeBuffer(buffer, 0, data);
    return buffer;
  };
  const room = (n) => device.createBuffer({ size: Math.max(16, 4 * n), usage: STORAGE });
  const tensors = new Map(exp.weights.tensors.map((t) => [t.name, t]));
  const tensor = (name) => {
    const t = tensors.get(name);
    const n = t.shape.reduce((a, b) => a * b, 1);
    return { buffer: upload(weights.subarray(t.offset, t.offset + n)), shape: t.shape };
  };
  const dense = (layer) => {
    const w = tensor(layer.weight);
    return { weight: w.buffer, bias: tensor(layer.bias).buffer, dIn: w.shape[0], dOut: w.shape[1] };
  };
  const mlp = (m) => ({ layers: m.layers.map(dense), activation: m.hidden_activation === 'siren' ? 2 : 1 });

  // Kernels: each reads a uniform block of u32 parameters at binding 0 (named in export.json,
  // unnamed ones zero) and storage buffers after it.
  const kernels = {};
  for (const k of exp.kernels) {
    const code = new TextDecoder().decode(await bytes('../' + k.wgsl));
    const module = device.createShaderModule({ code });
    const pipeline = device.createComputePipeline({ layout: 'auto', compute: { module, entryPoint: k.entry_point } });
    kernels[k.name] = { pipeline, k, word: new Map(k.params.map((p) => [p.name, p.word])) };
  }
  const dispatch = (pass, name, params, buffers, x, y = 1) => {
    const { pipeline, k, word } = kernels[name];
    const words = new Uint32Array(Math.ceil(k.param_words / 4) * 4);
    for (const [field, value] of Object.entries(params)) {
      if (!word.has(field)) throw new Error(`kernel ${name} has no parameter ${field}`);
      words[word.get(field)] = value;
    }
    const uniform = device.createBuffer({ size: words.byteLength, usage: GPUBufferUsage.UNIFORM | GPUBufferUsage.COPY_DST });
    device.queue.writeBuffer(uniform, 0, words);
    const entries = [{ binding: 0, resource: { buffer: uniform } }]
      .concat(buffers.map((buffer, i) => ({ binding: i + 1, resource: { buffer } })));
    pass.setPipeline(pipeline);
    pass.setBindGroup(0, device.createBindGroup({ layout: pipeline.getBindGroupLayout(0), entries }));
    pass.dispatchWorkgroups(x, y);
  };
  // Workgroups for `n` threads of a one-dimensional kernel.
  const groups = (name, n) => Math.ceil(n / kernels[name].k.workgroup_size[0]);
  // y = act(x·W[wRow..] + bias) over `rows` rows of `dIn` inputs: gemm.wgsl (tiles of
  // gemm_tile × gemm_tile) with m = rows, n = d_out, k = dIn, A = x (row stride dIn), B = W from
  // row wRow, a bias per column.
  const spare = room(4);
  const tile = exp.gemm_tile;
  const denseLayer = (pass, layer, x, rows, dIn, wRow, bias, activation, y) =>
    dispatch(pass, 'gemm', {
      m: rows, n: layer.dOut, k: dIn, a_rs: dIn, a_cs: 1, b_off: wRow * layer.dOut,
      b_rs: layer.dOut, b_cs: 1, c_rs: layer.dOut, bias: 1, activation,
    }, [x, layer.weight, bias, empty, y, spare], Math.ceil(layer.dOut / tile), Math.ceil(rows / tile));
  // An MLP: hidden layers take its activation, the last is linear; ping-pongs through `scratch`.
  const runMlp = (pass, m, x, rows, first, scratch, out) => {
    const last = m.layers.length - 1;
    m.layers.forEach((layer, i) => {
      const input = i === 0 ? x : scratch[i % 2];
      const output = i === last ? out : scratch[(i + 1) % 2];
      const activation = i === last ? 0 : m.activation;
      if (i === 0) denseLayer(pass, layer, input, rows, first.dIn, first.wRow, first.bias ?? layer.bias, activation, output);
      else denseLayer(pass, layer, input, rows, layer.dIn, 0, layer.bias, activation, output);
    });
  };

  // The networks: the paper's encoder, or the linear design's basis (export.json has one).
  const blocks = (exp.encoder?.blocks ?? []).map((b) => ({
    cIn: b.in_channels, cOut: b.out_channels, weight: tensor(b.weight).buffer, bias: tensor(b.bias).buffer,
  }));
  const [codeSize, perRow] = [exp.code_size, exp.inputs_per_pixel];
  const toCode = exp.encoder ? dense(exp.encoder.to_code) : null;
  const basis = exp.basis && [tensor(exp.basis.functions).buffer, tensor(exp.basis.solid_angles).buffer];
  const resolutions = upload(new Uint32Array(exp.tracks.find((t) => t.grid)?.grid.resolutions ?? [0, 0, 0, 0]));
  const tracks = exp.tracks.map((t) => ({
    kind: t.kind_code,
    index: upload(new Uint32Array(t.inputs)),
    count: t.inputs.length,
    width: t.width,
    grid: t.grid ? tensor(t.grid.table).buffer : null,
    // Its networks in the order they run, and how many run before the light enters.
    steps: t.steps.map((s) => ({ mlp: mlp(t[s.network]), ownRow: s.own_row, ownWidth: s.own_width, codeRows: s.code_rows })),
    kept: t.kept,
    coefficients: t.coefficients ?? 0,
  }));
  const empty = room(4);

  // The G-buffer's foreground pixels as rows of the networks' inputs.
  const per = ex.gbuffer.floats_per_pixel;
  const pixels = ex.width * ex.height;
  const foreground = [];
  for (let i = 0; i < pixels; i++) if (gbuffer[i * per + per - 1] > 0.5) foreground.push(i);
  const rows = foreground.length;
  const rowInputs = new Float32Array(rows * perRow);
  foreground.forEach((p, r) => rowInputs.set(gbuffer.subarray(p * per, p * per + perRow), r * perRow));
  const features = upload(rowInputs);
  const widest = Math.max(...tracks.flatMap((t) => [t.width, ...t.steps.flatMap((s) => s.mlp.layers.map((l) => l.dOut))]));
  const scratch = [room(rows * widest), room(rows * widest)];
  const outputs = tracks.map((t) => room(rows * t.steps.at(-1).mlp.layers.at(-1).dOut));
  const rgb = room(rows * 3);

  // 1. The light code (once per lighting change): the convolution blocks, then a dense layer;
  // or the map's projection on the basis. After its values, the factors combine.wgsl
  // multiplies each channel by: the map's divisor times the model's gain (here already one
  // product), then 1.
  const code = room(codeSize + 6);
  device.queue.writeBuffer(code, codeSize * 4, new Float32Array([...ex.light.scale, 1, 1, 1]));
  let encoder = device.createCommandEncoder();
  let pass = encoder.beginComputePass();
  let [h, w] = [ex.light.shape[1], ex.light.shape[2]];
  let x = upload(light);
  if (basis) {
    dispatch(pass, 'light_project', { size: exp.basis.size, texels: h * w, views: 1 }, [...basis, x, code],
      groups('light_project', codeSize));
  }
  for (const b of blocks) {
    const outputs = b.cOut * (h / 2) * (w / 2);
    const out = room(outputs);
    const threads = exp.encoder.block_threads_per_output * outputs;
    dispatch(pass, 'encoder_block', { c_in: b.cIn, h, w, views: 1 }, [x, b.weight, b.bias, out, empty],
      groups('encoder_block', threads));
    [x, h, w] = [out, h / 2, w / 2];
  }
  if (toCode) denseLayer(pass, toCode, x, 1, toCode.dIn, 0, toCode.bias, 0, code);

  // 2. What does not depend on the lighting (once per camera): each track's inputs, then its
  // networks before the light enters (`kept` of its `steps`; ŝ where it has a transfer
  // network). Where the light enters at the combine (a linear track) they are all of them,
  // the last writing the track's outputs (its transfer coefficients).
  const kept = tracks.map((t, i) => {
    const inputs = t.kept > 0 ? scratch[0] : room(rows * t.width);
    dispatch(pass, 'track_inputs', { rows, count: t.count, width: t.width, grid: t.grid ? 1 : 0 },
      [features, t.index, t.grid ?? empty, resolutions, inputs], groups('track_inputs', rows));
    let s = inputs;
    t.steps.slice(0, t.kept).forEach((step, j) => {
      const out = j === t.steps.length - 1 ? outputs[i] : room(rows * step.mlp.layers.at(-1).dOut);
      runMlp(pass, step.mlp, s, rows, { dIn: step.ownWidth, wRow: step.ownRow }, scratch, out);
      s = out;
    });
    return s;
  });
  pass.end();
  device.queue.submit([encoder.finish()]);

  // 3. Per lighting: the code's share of each shading network's first layer, the shading
  // networks, and exp (or, for a linear track, the dot products of its kept transfer
  // coefficients with the code), kd/ks and the map's scale (combine.wgsl).
  const relight = () => {
    const encoder = device.createCommandEncoder();
    const pass = encoder.beginComputePass();
    tracks.forEach((t, i) => {
      // The step the light enters, if any (the last).
      const step = t.steps[t.kept];
      if (!step) return;
      const first = step.mlp.layers[0];
      const bias = room(first.dOut);
      // b' = b + ê·W[code rows]: the first layer's code rows over one row.
      denseLayer(pass, first, code, 1, codeSize, step.codeRows[0], first.bias, 0, bias);
      // Then the rows that multiply the pixel's own inputs: before ê's (ŝ first), or after them.
      runMlp(pass, step.mlp, kept[i], rows, { dIn: step.ownWidth, wRow: step.ownRow, bias }, scratch, outputs[i]);
    });
    // The tracks' radiance summed into rgb one track per dispatch, the last scaled.
    tracks.forEach((t, i) => {
      const params = {
        rows, kind: t.kind, accumulate: i > 0 ? 1 : 0, scaled: i === tracks.length - 1 ? 1 : 0,
        scale_at: codeSize, coefficients: t.coefficients,
      };
      // One code for every row (code_stride 0): the views binding is not read.
      dispatch(pass, 'combine', params, [features, outputs[i], code, features, rgb], groups('combine', rows));
    });
    pass.end();
    const readback = device.createBuffer({ size: rows * 12, usage: GPUBufferUsage.MAP_READ | GPUBufferUsage.COPY_DST });
    encoder.copyBufferToBuffer(rgb, 0, readback, 0, rows * 12);
    device.queue.submit([encoder.finish()]);
    return readback;
  };
  const start = performance.now();
  const readback = relight();
  await readback.mapAsync(GPUMapMode.READ);
  const ms = performance.now() - start;
  const radiance = new Float32Array(readback.getMappedRange().slice(0));

  // Against the CPU engine: the largest difference over the brightest reference value.
  let peak = 0;
  let worst = 0;
  foreground.forEach((p, r) => {
    for (let c = 0; c < 3; c++) {
      const want = reference[p * 3 + c];
      peak = Math.max(peak, Math.abs(want));
      worst = Math.max(worst, Math.abs(radiance[r * 3 + c] - want));
    }
  });
  const error = worst / peak;

  const canvas = document.getElementById('frame');
  [canvas.width, canvas.height] = [ex.width, ex.height];
  const draw = () => {
    const gain = 2 ** Number(document.getElementById('exposure').value);
    const image = new ImageData(ex.width, ex.height);
    const srgb = (v) => 255 * (v <= 0.0031308 ? 12.92 * v : 1.055 * v ** (1 / 2.4) - 0.055);
    foreground.forEach((p, r) => {
      for (let c = 0; c < 3; c++) image.data[p * 4 + c] = srgb(Math.min(1, Math.max(0, radiance[r * 3 + c] * gain)));
    });
    for (let p = 0; p < pixels; p++) image.data[p * 4 + 3] = 255;
    canvas.getContext('2d').putImageData(image, 0, 0);
  };
  draw();
  document.getElementById('exposure').oninput = draw;
  status.textContent = `${rows} foreground pixels of ${ex.width}×${ex.height} under ${ex.map}, ` +
    `shaded in ${ms.toFixed(1)} ms (with read-back; adapter: ${adapter.info?.description || adapter.info?.vendor || 'unnamed'}).\n` +
    `Largest difference from the CPU engine: ${error.toExponential(2)} of the brightest value.`;
  return { rows, error, ms, image: canvas.toDataURL('image/png') };
}

main().then(
  async (result) => { if (report) await fetch('/result', { method: 'POST', body: JSON.stringify(result) }); },
  async (e) => {
    status.textContent = 'error: ' + e.message;
    if (report) await fetch('/result', { method: 'POST', body: JSON.stringify({ error: String(e.message) }) });
  },
);
