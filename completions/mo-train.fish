complete -c mo-train -l out -d 'Model directory to write (and to resume from)' -r -F
complete -c mo-train -l preset -d 'Model size: tiny (width 32, 2 layers), compact (width 64, 2 layers; for sata the same as small), small (width 64, 4 layers) or paper (width 128, 4 layers, 4 heads)' -r -f -a "tiny\t''
compact\t''
small\t''
paper\t''"
complete -c mo-train -l steps -d 'Training steps in total (a resumed run counts the steps already done) [default: 10000, or no limit with --minutes]' -r
complete -c mo-train -l minutes -d 'Train for this much wall time (this invocation\'s), then save and stop; with --steps, whichever comes first. The progress bar then shows the time left' -r
complete -c mo-train -l init -d 'anytop: start from a trained model instead of random weights: \'builtin\' (the model inside the binaries) or a model directory written by mo-train (use ./builtin for a directory of that name). A new run only: with --resume the checkpoint in --out goes on' -r -F
complete -c mo-train -l batch -d 'Crops per step [default: 16; with --init 4]' -r
complete -c mo-train -l crop -d 'Crop length in frames (default 40 for anytop, with --init 20; for sata the preset\'s window, 32 for small, which then is also the model\'s inference window)' -r
complete -c mo-train -l arch -d 'What to train: anytop (the diffusion model behind mo-sample, mo-dift and mo-segment) or sata (the topology-agnostic autoencoder behind mo-encode --latent and mo-retarget --method latent)' -r -f -a "anytop\t''
sata\t''"
complete -c mo-train -l lambda-kl -d 'sata: weight of the KL term that keeps the latent near a unit Gaussian' -r
complete -c mo-train -l lambda-cycle -d 'sata: weight of the cross-skeleton latent cycle (a motion\'s latent decoded onto another training skeleton and encoded again should come back). Default 0 for a new run (tried at 1 for 1,100 steps: transfers moved less, models/zoo-sata/MODEL_CARD.md); a resumed run keeps its checkpoint\'s unless this is given' -r
complete -c mo-train -l lr -d 'Learning rate [default: 1e-4; with --init 1e-3]' -r
complete -c mo-train -l lambda-geo -d 'Weight of the geodesic rotation loss (the angle, in radians, between predicted and true joint rotations) next to the MSE; the reference trains with 1' -r
complete -c mo-train -l lambda-vel -d 'Weight of a velocity loss next to the MSE: the squared error of the prediction\'s frame-to-frame changes against the motion\'s (normalised units; MDM\'s, not in AnyTop\'s reference). 0 = off. Not kept in the checkpoint: give it again with --resume' -r
complete -c mo-train -l augment -d 'Chance that a training draw uses an augmented skeleton (joints removed or added), as a number in [0, 1] or a fraction like 2/3 [default: 2/3; with --init 0]' -r
complete -c mo-train -l augment-variants -d 'Augmented variants prepared per skeleton (alternately removing and adding joints)' -r
complete -c mo-train -l fallback-stats -d 'anytop: what training normalises as sampling normalises a skeleton the model never saw (the rest pose as the mean, the skeletons\' average spreads) instead of by its own clips\' statistics, so that the model learns the condition it gets zero-shot. A model trained with `all` can go in another model\'s unseen/ folder, where mo-sample takes it for every skeleton that model was not trained on (the built-in model is such a pair) [default: none; with --resume the checkpoint\'s]' -r -f -a "none\t'Every skeleton and variant by its own clips (upstream\'s way)'
variants\t'The augmented variants (new topologies every one); the skeletons keep theirs, which sampling uses for them'
all\t'Every skeleton and variant, so the model has one condition; the checkpoint then records the fallback as each skeleton\'s statistics, and sampling uses it for them too'"
complete -c mo-train -l loss-units -d 'anytop: the units of the error of what --fallback-stats normalises: `own` measures it in the skeleton\'s own clips\' spreads, so a creature that moves little next to the average spread weighs as much as one that moves a lot (measured on the zoo: no better than `normalised`) [default: normalised; with --resume the checkpoint\'s]' -r -f -a "normalised\t'Every value alike, in the units it is normalised in'
own\t'A fallback-normalised value\'s squared error times (fallback spread / own spread)², clamped to `LOSS_WEIGHT_RANGE`'"
complete -c mo-train -l rest-token -d 'anytop: what the rest-pose token is normalised by: `skeleton` (its skeleton\'s statistics, as the motion: all zeros under the fallback, so the model never learns where a creature\'s legs point) or `global` (statistics pooled over the training skeletons\' rest poses, kept in the checkpoint, the same for every skeleton) [default: skeleton; with --resume the checkpoint\'s; with --init the model\'s]' -r -f -a "skeleton\t'The skeleton\'s own (or fallback) statistics, as the motion (upstream\'s way)'
global\t'Statistics pooled over the trained skeletons\' rest rows (`RestNorm`)'"
complete -c mo-train -l ema -d 'anytop: decay of the moving average of the weights that the saved model holds and mo-sample samples with (the raw weights are kept beside it for --resume). 0 = save the raw weights. An average over about 1/(1 - decay) steps' -r
complete -c mo-train -l noise-shift -d 'anytop: divide the cosine noise schedule\'s signal-to-noise ratio by S² at every step, so the slow, whole-crop directions of motion are drowned in noise early enough for sampling to choose a motion over many steps instead of settling on the mean pose in the first. 1 = AnyTop\'s schedule [default: 10 for a new run (3-skeleton proxy: samples\' motion energy 0.2 of the clips\' at 1, 0.4-0.6 at 10); a resumed run keeps its checkpoint\'s, unless this is given: then the model goes on learning under the new schedule]' -r
complete -c mo-train -l loss-weighting -d 'anytop: how the loss weighs the diffusion steps: `x0` (every step\'s x0 error alike, AnyTop\'s), `v` (× 1 + SNR, the error of a v-prediction: the nearly clean steps count more) or `min-snr[:G]` (× min(SNR, G), G = 5 by default: the noisy steps count by the signal they carry) [default: v for a new run (3-skeleton proxy: samples\' motion energy 0.47-0.74 of the clips\' against 0.34-0.61 with x0); a resumed run or a fine-tune keeps its model\'s, unless this is given]' -r
complete -c mo-train -l position-jitter -d 'anytop: start each training crop\'s temporal positions at a random offset from 0 to N, so the model sees the positions of samples up to N + --crop frames long; without it (0) a longer sample\'s motion fades past the crop length [default: 1000 for a new run; a fine-tune or a resumed run keeps its model\'s, unless this is given]' -r
complete -c mo-train -l shift-taper -d 'anytop: taper the noise shift: the schedule\'s early (nearly clean) steps are shifted hardly at all and its last steps in full, so the model also learns to denoise finely; under the whole shift the cleanest step keeps noise of a quarter of the signal\'s scale. An experiment: on a 1-skeleton proxy its samples were worse [default: false for a new run; a fine-tune or a resumed run keeps its model\'s, unless this is given: then the model goes on learning under the new schedule]' -r -f -a "true\t''
false\t''"
complete -c mo-train -l checkpoint-minutes -d 'Save a checkpoint at least this often' -r
complete -c mo-train -s o -l output -d 'Write output here instead of stdout (\'-\' = stdout). Files are written atomically' -r -F
complete -c mo-train -l seed -d 'Seed for everything random; the same seed and input give byte-identical output' -r
complete -c mo-train -l threads -d 'Worker threads (default: all cores; at most 256). Output never depends on this' -r
complete -c mo-train -l animation -d 'glTF inputs: the animation that becomes the motion, by name or by index from 0 (default: the first)' -r
complete -c mo-train -l fps -d 'glTF inputs: sample the animation at this frame rate (default: at its keyframe times)' -r
complete -c mo-train -l resume -d 'Continue from the checkpoint in --out'
complete -c mo-train -s q -l quiet -d 'Print nothing on stderr but errors'
complete -c mo-train -s v -l verbose -d 'Print more about what is happening on stderr'
complete -c mo-train -s h -l help -d 'Print help (see more with \'--help\')'
complete -c mo-train -s V -l version -d 'Print version'
