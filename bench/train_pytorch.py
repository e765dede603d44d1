"""PyTorch peer of `nprt bench train`: the same networks, batch and loss, timed the same way.

Layers mirror crates/nprt-net (encoder: 5 x [3x3 conv 32, ReLU, zero-padded skip, 2x2 max-pool]
then a dense layer to 64; the four transport designs with SIREN or ReLU layers; log-radiance
outputs through exp, scaled by the map mean; L1 on log(1 + x); Adam lr 1e-4, eps 1e-8).
Prints one JSON line per design. `--device cuda` runs it on the GPU, in f32 without TF32 (as
nprt computes), synchronising before the clock is read; `--autocast bf16` runs the forward pass
under bf16 autocast (f32 master weights), `--compile` compiles the forward pass and loss with
torch.compile (compile time falls in the warm-up steps).
"""

import argparse
import json
import math
import time

import torch
from torch import nn

OMEGA_0 = 30.0
FEAT = 19
CODE = 64
KD, KS = slice(12, 15), slice(15, 18)
DIFFUSE = [0, 1, 2, 9, 10, 11, 12, 13, 14]
SPECULAR = [0, 1, 2, 9, 10, 11, 15, 16, 17, 3, 4, 5, 6, 7, 8, 18]


class Mlp(nn.Module):
    def __init__(self, widths, act):
        super().__init__()
        self.layers = nn.ModuleList(nn.Linear(a, b) for a, b in zip(widths, widths[1:]))
        self.act = act
        if act == "siren":
            with torch.no_grad():
                for i, l in enumerate(self.layers):
                    bound = 1 / l.in_features if i == 0 else math.sqrt(6 / l.in_features) / OMEGA_0
                    l.weight.uniform_(-bound, bound)

    def forward(self, x):
        for i, l in enumerate(self.layers):
            x = l(x)
            if i + 1 < len(self.layers):
                x = torch.sin(OMEGA_0 * x) if self.act == "siren" else torch.relu(x)
        return x


class Encoder(nn.Module):
    def __init__(self, width):
        super().__init__()
        self.convs = nn.ModuleList(nn.Conv2d(3 if i == 0 else 32, 32, 3, padding=1) for i in range(5))
        self.fc = nn.Linear(32 * (width >> 5) * (width >> 6), CODE)

    def forward(self, x):
        for conv in self.convs:
            skip = x if x.shape[1] == 32 else nn.functional.pad(x, (0, 0, 0, 0, 0, 32 - x.shape[1]))
            x = nn.functional.max_pool2d(torch.relu(conv(x)) + skip, 2)
        return self.fc(x.flatten(1))


class Track(nn.Module):
    def __init__(self, design, kind, act):
        super().__init__()
        self.kind = kind
        self.inputs = {"diffuse": DIFFUSE, "specular": SPECULAR}.get(kind, list(range(FEAT)))
        n = len(self.inputs)
        out = 6 if kind == "albedo" else 3
        if design == "baseline":
            self.transfer = None
            self.shading = Mlp([CODE + n, 256, 256, 256, 256, 3], act)
        else:
            w = 172 if design == "dsep" else 256
            self.transfer = Mlp([n, w, w, 64], act)
            self.shading = Mlp([64 + CODE, w, w, out], "relu")

    def forward(self, f, code):
        x = f[:, self.inputs]
        if self.transfer is None:
            o = self.shading(torch.cat([code, x], 1))
        else:
            o = self.shading(torch.cat([self.transfer(x), code], 1))
        if self.kind == "full":
            return o.exp()
        if self.kind == "albedo":
            return f[:, KD] * o[:, :3].exp() + f[:, KS] * o[:, 3:].exp()
        return (f[:, KD] if self.kind == "diffuse" else f[:, KS]) * o.exp()


class Net(nn.Module):
    def __init__(self, design, act, width):
        super().__init__()
        self.encoder = Encoder(width)
        self.tracks = nn.ModuleList(Track(design, k, act) for k in TRACKS[design])

    def forward(self, f, light, view, scale):
        code = self.encoder(light)[view]
        return sum(t(f, code) for t in self.tracks) * scale


# The designs this peer has a PyTorch twin of (nprt's names, tested against its Design::ALL),
# each with its tracks.
TRACKS = {"baseline": ["full"], "prt": ["full"], "albedo": ["albedo"], "dsep": ["diffuse", "specular"]}


def main():
    p = argparse.ArgumentParser()
    p.add_argument("--designs", default=",".join(TRACKS))
    p.add_argument("--activation", default="")
    p.add_argument("--batch-size", type=int, default=16384)
    p.add_argument("--views", type=int, default=8)
    p.add_argument("--encoder-width", type=int, default=128)
    p.add_argument("--steps", type=int, default=10)
    p.add_argument("--warmup", type=int, default=2)
    p.add_argument("--threads", type=int, default=0)
    p.add_argument("--device", default="cpu", help="cpu or cuda")
    p.add_argument("--autocast", default="", help="bf16: forward under bf16 autocast")
    p.add_argument("--compile", action="store_true", help="torch.compile the forward and loss")
    a = p.parse_args()
    dev = torch.device(a.device)
    torch.backends.cuda.matmul.allow_tf32 = False
    torch.backends.cudnn.allow_tf32 = False
    sync = torch.cuda.synchronize if dev.type == "cuda" else (lambda: None)
    if a.threads:
        torch.set_num_threads(a.threads)
    torch.manual_seed(0)
    for design in a.designs.split(","):
        act = a.activation or ("relu" if design == "baseline" else "siren")
        net = Net(design, act, a.encoder_width).to(dev)
        opt = torch.optim.Adam(net.parameters(), lr=1e-4, eps=1e-8)
        b, w = a.batch_size, a.encoder_width
        f = torch.rand(b, FEAT, device=dev)
        ref = torch.rand(b, 3, device=dev) * 4
        light = torch.rand(a.views, 3, w // 2, w, device=dev)
        view = torch.randint(0, a.views, (b,), device=dev)
        scale = torch.rand(b, 1, device=dev) + 0.5

        def loss_of():
            with torch.autocast(dev.type, dtype=torch.bfloat16, enabled=a.autocast == "bf16"):
                pred = net(f, light, view, scale)
            return (torch.log1p(pred.float()) - torch.log1p(ref)).abs().mean()

        loss_fn = torch.compile(loss_of) if a.compile else loss_of

        def step():
            opt.zero_grad(set_to_none=True)
            loss_fn().backward()
            opt.step()

        for _ in range(a.warmup):
            step()
        sync()
        t = time.perf_counter()
        for _ in range(a.steps):
            step()
        sync()
        secs = time.perf_counter() - t
        transport = sum(p.numel() for p in net.tracks.parameters())
        print(json.dumps({
            "design": design,
            "activation": act,
            "transport_params": transport,
            "samples_per_s": b * a.steps / secs,
            "torch": torch.__version__,
            "threads": torch.get_num_threads(),
            "device": str(dev),
            "variant": ("compile" if a.compile else "eager") + "-" + (a.autocast or "f32"),
        }), flush=True)


if __name__ == "__main__":
    main()
